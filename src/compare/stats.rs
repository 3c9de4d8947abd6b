//! The statistics of a comparison: mean ± sd over seeds, and paired differences against the
//! first configuration with a percentile-bootstrap interval, an exact sign test and a
//! win/tie/loss count (paper-notes.md "Comparisons").

use rand::Rng as _;
use rand::SeedableRng;

/// Resamples of the bootstrap interval.
pub const BOOTSTRAP_RESAMPLES: usize = 10_000;
/// Seed of the bootstrap's RNG when none is given: the same data give the same interval.
pub const BOOTSTRAP_SEED: u64 = 0x636f_6e65;
/// The level below which a sign-test p-value is called significant.
pub const ALPHA: f64 = 0.05;

/// Mean and sample standard deviation of `xs` (n − 1 in the denominator; 0 for one value;
/// both NaN for none).
pub fn mean_sd(xs: &[f64]) -> (f64, f64) {
    let n = xs.len();
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let mean = xs.iter().sum::<f64>() / n as f64;
    if n == 1 {
        return (mean, 0.0);
    }
    let ss: f64 = xs.iter().map(|x| (x - mean) * (x - mean)).sum();
    (mean, (ss / (n - 1) as f64).sqrt())
}

/// The 95 % percentile-bootstrap interval of the mean of `xs`: `resamples` means of `n`
/// values drawn with replacement by `rng`, and their 2.5 % and 97.5 % quantiles. `None` for
/// no data.
pub fn bootstrap_mean_ci(xs: &[f64], resamples: usize, rng: &mut crate::Rng) -> Option<(f64, f64)> {
    let n = xs.len();
    if n == 0 || resamples == 0 {
        return None;
    }
    let mut means: Vec<f64> = (0..resamples)
        .map(|_| (0..n).map(|_| xs[rng.random_range(0..n)]).sum::<f64>() / n as f64)
        .collect();
    means.sort_by(f64::total_cmp);
    let at = |p: f64| means[((p * resamples as f64).floor() as usize).min(resamples - 1)];
    Some((at(0.025), at(0.975)))
}

/// The two-sided exact sign test: the probability, under "a win and a loss are equally
/// likely", of a split of `wins + losses` at least as uneven as the one seen (ties are left
/// out). 1 when there are no wins nor losses.
pub fn sign_test_p(wins: usize, losses: usize) -> f64 {
    let n = wins + losses;
    if n == 0 {
        return 1.0;
    }
    let k = wins.min(losses);
    // P(X ≤ k) for X ~ Binomial(n, 1/2), summed in log space so large n do not overflow.
    let ln_half_n = n as f64 * std::f64::consts::LN_2;
    let mut ln_c = 0.0; // ln C(n, 0)
    let mut tail = 0.0;
    for i in 0..=k {
        if i > 0 {
            ln_c += ((n - i + 1) as f64).ln() - (i as f64).ln();
        }
        tail += (ln_c - ln_half_n).exp();
    }
    (2.0 * tail).min(1.0)
}

/// Which way a measure is better.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Better {
    /// Larger values are better (q, θ_min).
    Higher,
    /// Smaller values are better (Hausdorff, flips, time).
    Lower,
}

/// One configuration against the first on one measure, over the (mesh, seed) pairs where
/// both ran.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Paired {
    /// pairs compared
    pub n: usize,
    /// mean of (configuration − first)
    pub mean_diff: f64,
    /// 95 % bootstrap interval of `mean_diff` (`None` without pairs)
    pub ci: Option<(f64, f64)>,
    /// pairs where the configuration is better, by the measure's direction
    pub wins: usize,
    /// pairs with equal values
    pub ties: usize,
    /// pairs where the configuration is worse
    pub losses: usize,
    /// two-sided exact sign-test p-value of wins against losses
    pub p_sign: f64,
    /// the sign test is below [`ALPHA`] and the interval leaves 0 out: both say the same
    pub significant: bool,
}

/// Compare paired values `(first, other)` on a measure where `better` says which way wins;
/// `seed` seeds the bootstrap (deterministic: the same pairs give the same result).
pub fn paired(pairs: &[(f64, f64)], better: Better, seed: u64) -> Paired {
    let diffs: Vec<f64> = pairs.iter().map(|(a, b)| b - a).collect();
    let (mut wins, mut ties, mut losses) = (0, 0, 0);
    for d in &diffs {
        let signed = match better {
            Better::Higher => *d,
            Better::Lower => -*d,
        };
        if signed > 0.0 {
            wins += 1;
        } else if signed < 0.0 {
            losses += 1;
        } else {
            ties += 1;
        }
    }
    let mut rng = crate::Rng::seed_from_u64(seed);
    let ci = bootstrap_mean_ci(&diffs, BOOTSTRAP_RESAMPLES, &mut rng);
    let p_sign = sign_test_p(wins, losses);
    let excludes_zero = ci.is_some_and(|(lo, hi)| lo > 0.0 || hi < 0.0);
    Paired {
        n: diffs.len(),
        mean_diff: mean_sd(&diffs).0,
        ci,
        wins,
        ties,
        losses,
        p_sign,
        significant: p_sign < ALPHA && excludes_zero,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_sample_sd_of_known_data() {
        let (m, s) = mean_sd(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert_eq!(m, 5.0);
        // Σ(x − 5)² = 32, over n − 1 = 7.
        assert!((s - (32.0f64 / 7.0).sqrt()).abs() < 1e-12);
        assert_eq!(mean_sd(&[3.0]), (3.0, 0.0));
        assert!(mean_sd(&[]).0.is_nan());
    }

    #[test]
    fn sign_test_p_is_the_exact_binomial_tail() {
        // n = 5, all wins: 2 · (1/32).
        assert_eq!(sign_test_p(5, 0), 2.0 / 32.0);
        // n = 6, 1 loss: 2 · (1 + 6) / 64.
        assert!((sign_test_p(5, 1) - 14.0 / 64.0).abs() < 1e-15);
        // n = 10, 2 losses: 2 · (1 + 10 + 45) / 1024.
        assert!((sign_test_p(8, 2) - 112.0 / 1024.0).abs() < 1e-15);
        // A balanced split caps at 1; no pairs is 1.
        assert_eq!(sign_test_p(3, 3), 1.0);
        assert_eq!(sign_test_p(0, 0), 1.0);
        // Symmetric in wins and losses.
        assert_eq!(sign_test_p(2, 9), sign_test_p(9, 2));
        // Large n stays finite and tiny.
        let p = sign_test_p(400, 0);
        assert!(p > 0.0 && p < 1e-100);
    }

    #[test]
    fn bootstrap_interval_contains_the_mean_and_is_deterministic() {
        let xs: Vec<f64> = (0..20).map(|i| 0.01 * i as f64 - 0.05).collect();
        let (m, _) = mean_sd(&xs);
        let mut a = crate::Rng::seed_from_u64(7);
        let mut b = crate::Rng::seed_from_u64(7);
        let ci = bootstrap_mean_ci(&xs, 2000, &mut a).expect("data");
        assert_eq!(Some(ci), bootstrap_mean_ci(&xs, 2000, &mut b));
        assert!(ci.0 <= m && m <= ci.1, "{ci:?} around {m}");
        assert!(ci.0 > xs[0] && ci.1 < xs[19], "narrower than the data");
        // Constant data: a zero-width interval at the value.
        let mut r = crate::Rng::seed_from_u64(1);
        assert_eq!(bootstrap_mean_ci(&[0.5; 4], 100, &mut r), Some((0.5, 0.5)));
    }

    #[test]
    fn paired_counts_wins_by_the_direction_and_marks_clear_gains() {
        // Ten pairs, every one 0.01 better: all wins, p = 2/1024, interval at 0.01.
        let pairs: Vec<(f64, f64)> = (0..10)
            .map(|i| (0.8 + 0.001 * i as f64, 0.81 + 0.001 * i as f64))
            .collect();
        let p = paired(&pairs, Better::Higher, 1);
        assert_eq!((p.wins, p.ties, p.losses, p.n), (10, 0, 0, 10));
        assert!((p.p_sign - 2.0 / 1024.0).abs() < 1e-15);
        assert!(p.significant);
        let (lo, hi) = p.ci.expect("pairs");
        assert!(lo <= p.mean_diff && p.mean_diff <= hi);
        // The same data where lower is better: all losses, still significant (two-sided).
        let q = paired(&pairs, Better::Lower, 1);
        assert_eq!((q.wins, q.losses), (0, 10));
        // Noise: alternating signs are not significant.
        let noisy: Vec<(f64, f64)> = (0..10)
            .map(|i| (1.0, 1.0 + if i % 2 == 0 { 0.01 } else { -0.01 }))
            .collect();
        let r = paired(&noisy, Better::Higher, 1);
        assert_eq!((r.wins, r.losses), (5, 5));
        assert!(!r.significant && r.p_sign == 1.0);
        // Equal values are ties, and too few pairs are never significant.
        let t = paired(&[(1.0, 1.0), (2.0, 3.0)], Better::Higher, 1);
        assert_eq!((t.wins, t.ties, t.losses), (1, 1, 0));
        assert!(!t.significant);
    }
}
