// Red-black projected SOR on a general stencil: the device side of the wgpu backend.
//
// The host substitutes REAL (f32 or f64), STENCIL (neighbours per node: 4 for the (r, z) grid,
// 6 for a later (r, phi, z) grid) and WG (threads per workgroup); unconstrained nodes have
// bounds +-(largest finite REAL). Nothing here knows the dimension of the grid: a node is a
// slot with STENCIL neighbour indices and normalised coefficients, so a 3D grid only changes
// the host-side assembly.
//
// Slot record in `cf` (REAL, STENCIL + 3 values): w_1 .. w_S, q, lo, hi, with w_s = w_ns / sum w
// and q = q_n / sum w (V); in `idx` (u32, STENCIL + 1 values): the node, then its neighbours.
// An update reads the other colour only, so all slots of one colour run in parallel:
//   x_n <- clamp(x_n + omega (q + sum_s w_s x_nb(s) - x_n), lo, hi).

alias real = REAL;

struct Params {
    // First slot of this dispatch (colour offset) and number of slots.
    offset: u32,
    count: u32,
    // 1: record the largest update of this dispatch in `largest`.
    track: u32,
    // Threads per row of a two-dimensional dispatch (more than 65535 workgroups).
    row: u32,
    omega: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read_write> x: array<real>;
@group(0) @binding(2) var<storage, read> cf: array<real>;
@group(0) @binding(3) var<storage, read> idx: array<u32>;
// Floating conductors, CSR: [0, nb]: first edge of block b; [nb + 1, 2 nb + 1]: first node;
// then the edge neighbours, then the block nodes (offsets relative to the header's end).
@group(0) @binding(4) var<storage, read> bidx: array<u32>;
// Edge weights (normalised by the block's sum), then one q per block.
@group(0) @binding(5) var<storage, read> bcf: array<real>;
// Largest update (bits of a non-negative f32: their order is the order of the values).
@group(0) @binding(6) var<storage, read_write> largest: atomic<u32>;

var<workgroup> part: array<real, WG>;
var<workgroup> scratch: array<f32, WG>;

// Workgroup maximum of d (all threads must call it), folded into `largest` by thread 0.
fn record_max(lid: u32, d: f32) {
    scratch[lid] = d;
    workgroupBarrier();
    var s = WG / 2u;
    loop {
        if s == 0u {
            break;
        }
        if lid < s {
            scratch[lid] = max(scratch[lid], scratch[lid + s]);
        }
        workgroupBarrier();
        s = s / 2u;
    }
    if lid == 0u {
        atomicMax(&largest, bitcast<u32>(scratch[0]));
    }
}

@compute @workgroup_size(WG)
fn sweep(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let k = gid.x + gid.y * P.row;
    var d = 0.0f;
    if k < P.count {
        let slot = P.offset + k;
        let c = slot * (STENCIL + 3u);
        let i = slot * (STENCIL + 1u);
        var t = cf[c + STENCIL];
        for (var s = 0u; s < STENCIL; s++) {
            t += cf[c + s] * x[idx[i + 1u + s]];
        }
        let n = idx[i];
        let old = x[n];
        let next = clamp(old + real(P.omega) * (t - old), cf[c + STENCIL + 1u], cf[c + STENCIL + 2u]);
        x[n] = next;
        d = f32(abs(next - old));
    }
    if P.track != 0u {
        record_max(lid, d);
    }
}

// One workgroup per floating conductor: its potential moves (over-relaxed) to the conductance-
// weighted mean of its outside neighbours plus its charge term.
@compute @workgroup_size(WG)
fn blocks(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let b = wid.x;
    let nb = P.count;
    let head = 2u * nb + 2u;
    let e0 = bidx[b];
    let e1 = bidx[b + 1u];
    let n0 = bidx[nb + 1u + b];
    let n1 = bidx[nb + 2u + b];
    var s: real = 0.0;
    for (var e = e0 + lid; e < e1; e += WG) {
        s += bcf[e] * x[bidx[head + e]];
    }
    part[lid] = s;
    workgroupBarrier();
    var h = WG / 2u;
    loop {
        if h == 0u {
            break;
        }
        if lid < h {
            part[lid] += part[lid + h];
        }
        workgroupBarrier();
        h = h / 2u;
    }
    let nodes = head + bidx[nb];
    let old = x[bidx[nodes + n0]];
    let next = old + real(P.omega) * (part[0] + bcf[bidx[nb] + b] - old);
    workgroupBarrier();
    for (var m = n0 + lid; m < n1; m += WG) {
        x[bidx[nodes + m]] = next;
    }
    if P.track != 0u && lid == 0u {
        atomicMax(&largest, bitcast<u32>(f32(abs(next - old))));
    }
}
