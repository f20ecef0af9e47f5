//! The shipped stand-in curve carries the noise its covariance states (issue 23, item 3): its
//! truth (the exact solver's curve) against the measured curve with the measured covariance
//! alone gives a chi^2 inside the central 99% of chi^2 with 60 degrees of freedom, and every
//! point lies above the truth by the calibration factor `synthesize --draw-calibration` drew
//! (`raw/truth.json`). The likelihoods the fits use add the model's uncertainties (the paper's
//! solver term 1% + 1 pF, eq. 7, and the surrogate's), which a curve made by the same solver
//! does not carry, so their chi^2 lies far below ndf; the numbers are printed.

use hpge_validation::studies::stand_in::{shipped_stand_in, stand_in_noise};

#[test]
fn the_stand_in_carries_the_noise_of_its_covariance() {
    let s = stand_in_noise(&shipped_stand_in()).unwrap();
    eprintln!(
        "chi^2 of the truth curve for {} points: {:.1} with the measured covariance (p = {:.2}, \
         99% band [{:.1}, {:.1}]); {:.3} with the solver term added; {:.2} with the paper's \
         independent 3% term",
        s.points,
        s.chi2_measured,
        s.p_value,
        s.band_99[0],
        s.band_99[1],
        s.chi2_with_solver,
        s.chi2_paper
    );
    assert_eq!(s.points, 60);
    assert!(
        (s.band_99[0]..=s.band_99[1]).contains(&s.chi2_measured),
        "chi^2 {} (p = {}): the stand-in does not carry the noise its covariance states",
        s.chi2_measured,
        s.p_value
    );
    // The drawn calibration: one factor shared by every point, to the pulses' statistics.
    let f = s
        .calibration_factor
        .expect("raw/truth.json records the drawn calibration (synthesize --draw-calibration)");
    assert!(
        (f - 1.0).abs() > 1e-4,
        "no calibration error was drawn: {f}"
    );
    let worst = s.max_rel_from_factor.unwrap();
    assert!(worst < 5e-4, "a point is {worst} off the truth times {f}");
}
