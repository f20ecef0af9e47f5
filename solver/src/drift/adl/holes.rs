//! Holes: the anisotropic drift model of Bruyneel et al., NIM A 569 (2006) 764, section 3.
//!
//! In the crystal frame let the field direction have polar angle theta (from <001>) and azimuth
//! phi (from <100>). With v100, v111 the measured longitudinal velocities at the field's
//! magnitude and vrel = v111 / v100, the velocity in the spherical basis (e_r along E) is
//!
//! v_r     = v100 [1 - Lambda (sin^4 theta sin^2 2phi + sin^2 2theta)],
//! v_theta = v100 Omega [2 sin^3 theta cos theta sin^2 2phi + sin 4theta],
//! v_phi   = v100 Omega sin^3 theta sin 4phi,
//!
//! Lambda = 3/4 (1 - vrel), Omega = p1 x + p2 x^2 + p3 x^3 + p4 x^4 with x = 1 - vrel and
//! (p1, p2, p3, p4) = (-0.29711, -1.12082, 3.83929, 4.80825): Bruyneel's k0 parametrisation
//! (eqs. 22-26) expressed directly in vrel, as SolidStateDetectors.jl evaluates it for HPGe.
//! Along <100> (theta = 0) v = v100 e_r; along <111> (sin^2 theta = 2/3, phi = 45 deg) the
//! bracket of v_r is 4/3, so v_r = v111, and v_theta = v_phi = 0.

/// Coefficients of Omega(x), x = 1 - v111/v100, for germanium.
const OMEGA_GE: [f64; 4] = [-0.29711, -1.12082, 3.83929, 4.80825];

/// Hole drift velocity (crystal frame, units of `v100`) for the unit field direction `u`
/// (crystal frame) and the longitudinal velocities `v100`, `v111` at the field's magnitude
/// (Bruyneel et al. 2006, eqs. 22-26; formulas in the module documentation). Zero when `v100`
/// is not positive.
pub(super) fn velocity(u: [f64; 3], v100: f64, v111: f64) -> [f64; 3] {
    if v100.is_nan() || v100 <= 0.0 {
        return [0.0; 3];
    }
    let vrel = v111 / v100;
    let x = 1.0 - vrel;
    let lambda = 0.75 * x;
    let [p1, p2, p3, p4] = OMEGA_GE;
    let omega = x * (p1 + x * (p2 + x * (p3 + x * p4)));
    let theta = u[2].clamp(-1.0, 1.0).acos();
    let phi = u[1].atan2(u[0]);
    let (st, ct) = theta.sin_cos();
    let (s2t, c2t) = (2.0 * theta).sin_cos();
    let (s2p, c2p) = (2.0 * phi).sin_cos();
    let vr = v100 * (1.0 - lambda * (st.powi(4) * s2p * s2p + s2t * s2t));
    let vt = v100 * omega * 2.0 * (st.powi(3) * ct * s2p * s2p + s2t * c2t);
    let vp = v100 * omega * 2.0 * st.powi(3) * s2p * c2p;
    let (sp, cp) = phi.sin_cos();
    let e_r = [st * cp, st * sp, ct];
    let e_t = [ct * cp, ct * sp, -st];
    let e_p = [-sp, cp, 0.0];
    std::array::from_fn(|k| vr * e_r[k] + vt * e_t[k] + vp * e_p[k])
}
