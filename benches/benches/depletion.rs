//! Depletion voltages with their error bars (issue 64): for every shipped detector type of the
//! accuracy table (`hpge_validation::accuracy_cases`) that depletes, the full-depletion voltage
//! U_fd with its error bar on the fully depleted reference's grid
//! (`field::full_depletion_voltage_estimate`: two linear solves on the grid and on each of its two
//! coarsenings, bisection by flood fills), bracketed by the case's last undepleted bias and its
//! depleted one; for the types with a pocket window (the ICPCs), the pinch-off voltage with its
//! error bar (`field::pinch_off_voltage_estimate`: nonlinear solves with pockets, bisected),
//! bracketed by the undepleted and pinch-off-window biases. The grid is computed once, outside
//! the timing (it is the cached reference every fully depleted point of a curve uses).

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use hpge_solver::field::{full_depletion_voltage_estimate, pinch_off_voltage_estimate};
use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::{accuracy_cases, repo_path};

pub fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("depletion");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for case in accuracy_cases() {
        let det = Detector::from_file(&repo_path(case.detector), &Parameters::new())
            .expect("shipped detector loads");
        let s = FieldSettings::default().for_detector(&det);
        let name = case
            .detector
            .trim_start_matches("detectors/")
            .trim_end_matches(".toml");
        let depleted = case.biases.iter().find(|(_, k)| *k == "depleted");
        let (Some(&(hi, _)), Some(&(lo, _))) = (depleted, case.biases.first()) else {
            continue;
        };
        let grid = solve_point(&det, hi, &s, None).expect("solves").mesh.grid;
        // The case's last bias below the depleted one brackets U_fd from below.
        let below = case
            .biases
            .iter()
            .map(|(v, _)| *v)
            .filter(|v| *v < hi)
            .fold(lo, f64::max);
        g.bench_function(format!("u_fd_with_error/{name}"), |b| {
            b.iter(|| {
                full_depletion_voltage_estimate(&det, &grid, black_box(below), hi)
                    .expect("solves")
                    .expect("depletes")
            })
        });
        if let Some(&(window, _)) = case.biases.iter().find(|(_, k)| *k == "pinch-off") {
            g.bench_function(format!("pinch_off_with_error/{name}"), |b| {
                b.iter(|| {
                    pinch_off_voltage_estimate(&det, &grid, (black_box(lo), window), hi)
                        .expect("solves")
                        .expect("a pocket forms")
                })
            });
        }
    }
    g.finish();
}
