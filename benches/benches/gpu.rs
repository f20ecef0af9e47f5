//! The two backends side by side: one potential solve (with depletion, from the default initial
//! iterate) and one weighting-potential solve (all contacts) of super-siegfried-k1 at 1025 V
//! on three grids (crystal spacing 2, 1 and 0.5 mm, no refinement): CPU `fast` (active set with
//! sparse Cholesky), CPU `sor`, and `sor` on the wgpu backend at the adapter's precision.
//! CPU weighting potentials are one sparse Cholesky factorisation and two solves.
//!
//! On Mesa's lavapipe (a software Vulkan, as in CI) the wgpu numbers are correctness runs, not
//! speed claims. Without an adapter the wgpu benches are skipped with one line.
//!
//! `HPGE_BENCH_LARGE=1` adds two finer grids (0.25 and 0.125 mm, about 50 000 and 200 000
//! nodes: where a hardware GPU can pay for its launches) and the wgpu potential with 50 sweeps
//! per submission and read-back instead of 10 (`wgpu_sor_check50`); `HPGE_BENCH_SECONDS=S`
//! sets each bench's measurement time (default 10 s; criterion still takes its 10 samples).

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use hpge_solver::field::{
    Mesh, SorSettings, solve_fast, solve_sor, solve_sor_wgpu, solve_sor_wgpu_with,
    weighting_potentials, weighting_potentials_wgpu,
};
use hpge_solver::gpu::gpu_adapter;
use hpge_solver::grid::Grid;
use hpge_solver::{Detector, GridSettings, Parameters, Precision};
use hpge_validation::repo_path;

const BIAS_V: f64 = 1025.0;

pub fn bench(c: &mut Criterion) {
    let det = Detector::from_file(
        &repo_path("detectors/super-siegfried-k1.toml"),
        &Parameters::new(),
    )
    .expect("shipped detector loads");
    let gpu = match gpu_adapter() {
        Ok(a) => {
            eprintln!(
                "wgpu adapter: {} ({}, {}, {})",
                a.name,
                a.api,
                a.device_type,
                if a.shader_f64 { "f64" } else { "f32" }
            );
            true
        }
        Err(e) => {
            eprintln!("skipping the wgpu benches: {e}");
            false
        }
    };
    let mut g = c.benchmark_group("backends");
    let seconds = std::env::var("HPGE_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(10);
    g.sample_size(10)
        .measurement_time(Duration::from_secs(seconds.max(1)));
    let large = std::env::var("HPGE_BENCH_LARGE").is_ok_and(|v| v == "1");
    let mut spacings = vec![2.0, 1.0, 0.5];
    if large {
        spacings.extend([0.25, 0.125]);
    }
    let check50 = SorSettings {
        check_every: 50,
        ..SorSettings::default()
    };
    for spacing in spacings {
        let gs = GridSettings {
            max_spacing_semiconductor_mm: spacing,
            max_spacing_mm: 4.0 * spacing,
            ..GridSettings::default()
        };
        let mesh = Mesh::new(&det, Grid::initial(&det, &gs));
        let nodes = mesh.kind.len();
        let pot = solve_fast(&mesh, &det, BIAS_V, None).expect("solves");
        g.bench_function(format!("potential/cpu_fast/{nodes}"), |b| {
            b.iter(|| solve_fast(&mesh, &det, black_box(BIAS_V), None).expect("solves"))
        });
        g.bench_function(format!("potential/cpu_sor/{nodes}"), |b| {
            b.iter(|| solve_sor(&mesh, &det, black_box(BIAS_V), None).expect("solves"))
        });
        g.bench_function(format!("weighting/cpu/{nodes}"), |b| {
            b.iter(|| {
                weighting_potentials(&mesh, &det, black_box(&pot.undepleted), BIAS_V)
                    .expect("solves")
            })
        });
        if gpu {
            g.bench_function(format!("potential/wgpu_sor/{nodes}"), |b| {
                b.iter(|| {
                    solve_sor_wgpu(&mesh, &det, black_box(BIAS_V), None, Precision::Auto)
                        .expect("solves")
                })
            });
            if large {
                g.bench_function(format!("potential/wgpu_sor_check50/{nodes}"), |b| {
                    b.iter(|| {
                        solve_sor_wgpu_with(
                            &mesh,
                            &det,
                            black_box(BIAS_V),
                            None,
                            &check50,
                            Precision::Auto,
                        )
                        .expect("solves")
                    })
                });
            }
            g.bench_function(format!("weighting/wgpu_sor/{nodes}"), |b| {
                b.iter(|| {
                    weighting_potentials_wgpu(
                        &mesh,
                        &det,
                        black_box(&pot.undepleted),
                        BIAS_V,
                        Precision::Auto,
                    )
                    .expect("solves")
                })
            });
        }
    }
    g.finish();
}
