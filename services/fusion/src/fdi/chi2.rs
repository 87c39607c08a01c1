//! χ² distribution tail and quantile, for the parity test threshold.
//!
//! The survival function of χ²(k) is the regularised upper incomplete gamma function
//! `Q(k/2, x/2)`. `Q` is evaluated by its power series (`x < a + 1`, as `1 − P`) or by its
//! continued fraction (`x ≥ a + 1`, directly, so tiny tail probabilities keep full relative
//! precision). The quantile is found by bisection on `ln Q`, which is monotone in x; it is only
//! evaluated at construction and reconfiguration, never per sample.

/// Why a χ² quantile cannot be computed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum Chi2Error {
    /// Zero degrees of freedom were asked for.
    #[error("χ² degrees of freedom = {0}: must be >= 1")]
    DegreesOfFreedom(usize),
    /// The tail probability is not strictly between 0 and 1.
    #[error("tail probability = {0}: must be in (0, 1)")]
    Probability(f64),
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms; relative error below 1e-14).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const COEF: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection keeps the series in its accurate range.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + G + 0.5;
    let sum = COEF
        .iter()
        .enumerate()
        .skip(1)
        .fold(COEF[0], |acc, (i, c)| acc + c / (x + i as f64));
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

const EPS: f64 = 1e-16;
const MAX_ITERATIONS: usize = 10_000;

/// ln of `x^a e^{-x} / Γ(a)`, the common prefactor of both expansions.
fn ln_prefactor(a: f64, x: f64) -> f64 {
    a * x.ln() - x - ln_gamma(a)
}

/// P(a, x) by its series; accurate for x < a + 1.
fn lower_series(a: f64, x: f64) -> f64 {
    let mut term = 1.0 / a;
    let mut sum = term;
    let mut ap = a;
    for _ in 0..MAX_ITERATIONS {
        ap += 1.0;
        term *= x / ap;
        sum += term;
        if term.abs() < sum.abs() * EPS {
            break;
        }
    }
    sum * ln_prefactor(a, x).exp()
}

/// Q(a, x) by its continued fraction (modified Lentz); accurate for x ≥ a + 1.
fn upper_continued_fraction(a: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..MAX_ITERATIONS {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < TINY {
            d = TINY;
        }
        c = b + an / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < EPS {
            break;
        }
    }
    (ln_prefactor(a, x) + h.ln()).exp()
}

/// Regularised lower incomplete gamma function P(a, x), a > 0, x ≥ 0.
pub fn regularized_gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x < a + 1.0 {
        lower_series(a, x)
    } else {
        1.0 - upper_continued_fraction(a, x)
    }
}

/// Regularised upper incomplete gamma function Q(a, x) = 1 − P(a, x), a > 0, x ≥ 0.
pub fn regularized_gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        1.0
    } else if x < a + 1.0 {
        1.0 - lower_series(a, x)
    } else {
        upper_continued_fraction(a, x)
    }
}

/// P(X > x) for X ~ χ²(dof).
pub fn chi2_survival(x: f64, dof: usize) -> f64 {
    regularized_gamma_q(dof as f64 / 2.0, x / 2.0)
}

/// The x with P(X > x) = `tail` for X ~ χ²(dof): the detection threshold for a false-alarm
/// probability `tail` per sample. Relative accuracy about 1e-12.
pub fn chi2_upper_quantile(dof: usize, tail: f64) -> Result<f64, Chi2Error> {
    if dof == 0 {
        return Err(Chi2Error::DegreesOfFreedom(dof));
    }
    if !(tail > 0.0 && tail < 1.0) {
        return Err(Chi2Error::Probability(tail));
    }
    let target = tail.ln();
    let ln_tail = |x: f64| chi2_survival(x, dof).ln();
    let mut lo = 0.0;
    let mut hi = dof as f64 + 10.0;
    // The χ² tail decays like e^{-x/2}, so doubling brackets any tail above 1e-300 quickly.
    while ln_tail(hi) > target {
        lo = hi;
        hi *= 2.0;
        if hi > 1e6 {
            return Err(Chi2Error::Probability(tail));
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ln_tail(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-13 * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_gamma_matches_factorials_and_half_integers() {
        let mut factorial = 1.0_f64;
        for n in 1..30 {
            // Γ(n) = (n − 1)!
            assert!((ln_gamma(n as f64) - factorial.ln()).abs() < 1e-12 * factorial.ln().max(1.0));
            factorial *= n as f64;
        }
        let sqrt_pi = std::f64::consts::PI.sqrt();
        assert!((ln_gamma(0.5) - sqrt_pi.ln()).abs() < 1e-14);
        assert!((ln_gamma(1.5) - (0.5 * sqrt_pi).ln()).abs() < 1e-14);
    }

    #[test]
    fn p_and_q_are_complementary_and_match_the_exponential_case() {
        // a = 1: P(1, x) = 1 − e^{-x}.
        for x in [0.01, 0.5, 1.0, 2.0, 5.0, 30.0] {
            assert!((regularized_gamma_p(1.0, x) - (1.0 - (-x).exp())).abs() < 1e-14);
            assert!(((regularized_gamma_q(1.0, x) - (-x).exp()) / (-x).exp()).abs() < 1e-12);
            for a in [0.5, 2.5, 7.0] {
                let s = regularized_gamma_p(a, x) + regularized_gamma_q(a, x);
                assert!((s - 1.0).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn rejects_bad_arguments() {
        assert_eq!(
            chi2_upper_quantile(0, 0.1),
            Err(Chi2Error::DegreesOfFreedom(0))
        );
        assert_eq!(
            chi2_upper_quantile(2, 0.0),
            Err(Chi2Error::Probability(0.0))
        );
        assert_eq!(
            chi2_upper_quantile(2, 1.0),
            Err(Chi2Error::Probability(1.0))
        );
        assert!(chi2_upper_quantile(2, f64::NAN).is_err());
    }
}
