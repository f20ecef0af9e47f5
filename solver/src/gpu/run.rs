//! Running a [`StencilProblem`] on the device: upload once, record `check_every` sweeps per
//! submission, reduce the largest update of the last one on the device, read back 4 bytes, and
//! read the potential back once at the end.

use std::sync::mpsc;

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::context::{Gpu, WORKGROUP};
use super::stencil::StencilProblem;
use crate::error::{Error, Result};
use crate::relaxation::{SorSettings, StopRule};

/// Uniform parameters of one dispatch (layout of `Params` in sor.wgsl).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct Params {
    offset: u32,
    count: u32,
    track: u32,
    row: u32,
    omega: f32,
    pad: [u32; 3],
}

/// What a device solve returns.
#[derive(Debug, Clone)]
pub(crate) struct DeviceSolution {
    /// Every node, V (converted to f64).
    pub(crate) x: Vec<f64>,
    /// Red-black sweeps done.
    pub(crate) sweeps: usize,
    /// False when `max_sweeps` ran out or an update was not finite (x is the last iterate).
    pub(crate) converged: bool,
}

/// Values in the device's precision, as bytes.
fn reals(v: impl Iterator<Item = f64>, f64: bool) -> Vec<u8> {
    if f64 {
        let v: Vec<f64> = v.map(|a| a.clamp(f64::MIN, f64::MAX)).collect();
        bytemuck::cast_slice(&v).to_vec()
    } else {
        let v: Vec<f32> = v.map(|a| (a as f32).clamp(f32::MIN, f32::MAX)).collect();
        bytemuck::cast_slice(&v).to_vec()
    }
}

/// Pads a byte vector to at least 16 bytes and a multiple of 4 (bindings cannot be empty).
fn padded(mut b: Vec<u8>) -> Vec<u8> {
    let len = b.len().max(16).next_multiple_of(4);
    b.resize(len, 0);
    b
}

/// Solves `p` on the device with `settings` (omega from the problem; the stopping rule of
/// [`StopRule`] in the device's unit round-off). A solve that ran out of sweeps or diverged
/// comes back with `converged: false`; errors are device failures ([`Error::Gpu`]).
pub(crate) fn run(
    gpu: &Gpu,
    p: &StencilProblem,
    settings: &SorSettings,
    f64: bool,
) -> Result<DeviceSolution> {
    let dev = &gpu.device;
    let k = gpu.kernels(f64, p.stencil)?;
    let s = p.stencil;
    let oom = dev.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = dev.push_error_scope(wgpu::ErrorFilter::Validation);

    // Slot records: colour 0, then colour 1.
    let mut cf = Vec::new();
    let mut idx: Vec<u32> = Vec::new();
    for c in &p.colours {
        for slot in 0..c.node.len() {
            cf.extend_from_slice(&c.w[slot * s..(slot + 1) * s]);
            cf.extend_from_slice(&[c.q[slot], c.lo[slot], c.hi[slot]]);
            idx.push(c.node[slot]);
            idx.extend_from_slice(&c.nb[slot * s..(slot + 1) * s]);
        }
    }
    // Floating conductors, CSR (see sor.wgsl).
    let nb = p.blocks.len();
    let mut bidx: Vec<u32> = Vec::with_capacity(2 * nb + 2);
    let mut e = 0u32;
    bidx.push(0);
    for b in &p.blocks {
        e += b.edges.len() as u32;
        bidx.push(e);
    }
    let mut m = 0u32;
    bidx.push(0);
    for b in &p.blocks {
        m += b.nodes.len() as u32;
        bidx.push(m);
    }
    let mut bcf = Vec::new();
    for b in &p.blocks {
        bidx.extend(b.edges.iter().map(|e| e.0));
        bcf.extend(b.edges.iter().map(|e| e.1));
    }
    for b in &p.blocks {
        bidx.extend_from_slice(&b.nodes);
    }
    bcf.extend(p.blocks.iter().map(|b| b.q));

    let storage = wgpu::BufferUsages::STORAGE;
    let init = |label: &str, contents: Vec<u8>, usage| {
        dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: &padded(contents),
            usage,
        })
    };
    let copy = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let x_buf = init("x", reals(p.x0.iter().copied(), f64), storage | copy);
    let cf_buf = init("cf", reals(cf.into_iter(), f64), storage);
    let idx_buf = init("idx", bytemuck::cast_slice(&idx).to_vec(), storage);
    let bidx_buf = init("bidx", bytemuck::cast_slice(&bidx).to_vec(), storage);
    let bcf_buf = init("bcf", reals(bcf.into_iter(), f64), storage);
    let largest = init("largest", vec![0; 4], storage | copy);
    let x_bytes = (p.x0.len() * if f64 { 8 } else { 4 }) as u64;
    let read = |label: &str, size: u64| {
        dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    };
    let largest_read = read("largest read", 4);
    let x_read = read("x read", x_bytes);

    // Dispatch geometry: more than max_per_dim workgroups spill into a second dimension.
    let max_per_dim = dev.limits().max_compute_workgroups_per_dimension.max(1);
    let row = max_per_dim * WORKGROUP;
    let groups = |count: u32| {
        let wg = count.div_ceil(WORKGROUP);
        (wg.min(max_per_dim), wg.div_ceil(max_per_dim))
    };
    let bind = |params: Params| {
        let u = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sor"),
            layout: &k.layout,
            entries: &[
                (0, &u),
                (1, &x_buf),
                (2, &cf_buf),
                (3, &idx_buf),
                (4, &bidx_buf),
                (5, &bcf_buf),
                (6, &largest),
            ]
            .map(|(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            }),
        })
    };
    let counts = [
        p.colours[0].node.len() as u32,
        p.colours[1].node.len() as u32,
    ];
    let params = |offset, count, track: bool| Params {
        offset,
        count,
        track: u32::from(track),
        row,
        omega: p.omega as f32,
        pad: [0; 3],
    };
    // [untracked, tracked] bind groups of red, black and the blocks.
    let red = [false, true].map(|t| bind(params(0, counts[0], t)));
    let black = [false, true].map(|t| bind(params(counts[0], counts[1], t)));
    let blocks = [false, true].map(|t| bind(params(0, nb as u32, t)));

    let eps = if f64 {
        f64::EPSILON
    } else {
        f32::EPSILON as f64
    };
    let mut rule = StopRule::new(settings, p.scale_v, p.magnitude_v, eps);
    let mut sweeps = 0;
    let converged = loop {
        let batch = settings
            .check_every
            .min(settings.max_sweeps - sweeps)
            .max(1);
        let mut enc = dev.create_command_encoder(&Default::default());
        enc.clear_buffer(&largest, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            for b in 0..batch {
                let t = usize::from(b + 1 == batch);
                pass.set_pipeline(&k.sweep);
                for (bg, count) in [(&red[t], counts[0]), (&black[t], counts[1])] {
                    if count > 0 {
                        let (gx, gy) = groups(count);
                        pass.set_bind_group(0, bg, &[]);
                        pass.dispatch_workgroups(gx, gy, 1);
                    }
                }
                if nb > 0 {
                    pass.set_pipeline(&k.blocks);
                    pass.set_bind_group(0, &blocks[t], &[]);
                    pass.dispatch_workgroups(nb as u32, 1, 1);
                }
            }
        }
        enc.copy_buffer_to_buffer(&largest, 0, &largest_read, 0, 4);
        gpu.queue.submit([enc.finish()]);
        sweeps += batch;
        let bits = read_back(gpu, &largest_read, 4)?;
        let d = f32::from_bits(u32::from_le_bytes([bits[0], bits[1], bits[2], bits[3]])) as f64;
        match rule.converged(d) {
            Some(true) => break true,
            Some(false) if sweeps < settings.max_sweeps => {}
            _ => break false,
        }
    };
    let mut enc = dev.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(&x_buf, 0, &x_read, 0, x_bytes);
    gpu.queue.submit([enc.finish()]);
    let bytes = read_back(gpu, &x_read, x_bytes)?;
    let x: Vec<f64> = if f64 {
        bytemuck::pod_collect_to_vec::<u8, f64>(&bytes)
    } else {
        bytemuck::pod_collect_to_vec::<u8, f32>(&bytes)
            .into_iter()
            .map(f64::from)
            .collect()
    };
    for (scope, what) in [(validation, "validation"), (oom, "out of memory")] {
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Gpu {
                message: format!("{what} error on `{}`: {e}", gpu.report.name),
            });
        }
    }
    Ok(DeviceSolution {
        x,
        sweeps,
        converged,
    })
}

/// Maps `buf` (after the submitted copies into it), waits, returns its first `len` bytes.
fn read_back(gpu: &Gpu, buf: &wgpu::Buffer, len: u64) -> Result<Vec<u8>> {
    let slice = buf.slice(..len);
    let (tx, rx) = mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    let fail = |what: String| Error::Gpu {
        message: format!("reading back from `{}`: {what}", gpu.report.name),
    };
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| fail(e.to_string()))?;
    rx.recv()
        .map_err(|e| fail(e.to_string()))?
        .map_err(|e| fail(e.to_string()))?;
    let out = slice
        .get_mapped_range()
        .map_err(|e| fail(e.to_string()))?
        .to_vec();
    buf.unmap();
    Ok(out)
}
