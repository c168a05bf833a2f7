//! Distances between two samples.
//!
//! - Jensen–Shannon divergence of two histograms, base 2 (0: same, 1: disjoint).
//! - Wasserstein-1 between two empirical distributions on the line (the area between the
//!   CDFs).
//! - Squared MMD, the unbiased estimate, with a Gaussian kernel whose bandwidth is the
//!   median pairwise distance of the pooled points (fixed once, so bootstrap resamples
//!   share one kernel matrix).
//! - Fréchet distance of Gaussians fitted to two point sets:
//!   |μa − μb|² + tr Σa + tr Σb − 2 tr (Σa Σb)^½. With Σa = AAᵀ and Σb = BBᵀ (centred
//!   points over √(n−1)), tr (Σa Σb)^½ is the sum of the singular values of AᵀB, an
//!   na×nb matrix: no d×d square root, exact when there are fewer points than dimensions.

use std::collections::BTreeMap;

pub fn jsd(a: &BTreeMap<String, u32>, b: &BTreeMap<String, u32>) -> f64 {
    let ta: u32 = a.values().sum();
    let tb: u32 = b.values().sum();
    if ta == 0 && tb == 0 {
        return 0.0;
    }
    if ta == 0 || tb == 0 {
        return 1.0;
    }
    let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
    keys.sort();
    keys.dedup();
    let mut d = 0.0;
    for k in keys {
        let p = a.get(k).copied().unwrap_or(0) as f64 / ta as f64;
        let q = b.get(k).copied().unwrap_or(0) as f64 / tb as f64;
        let m = (p + q) / 2.0;
        if p > 0.0 {
            d += 0.5 * p * (p / m).log2();
        }
        if q > 0.0 {
            d += 0.5 * q * (q / m).log2();
        }
    }
    d.clamp(0.0, 1.0)
}

pub fn wasserstein1(a: &[f64], b: &[f64]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return f64::NAN;
    }
    let mut a = a.to_vec();
    let mut b = b.to_vec();
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    let mut points: Vec<f64> = a.iter().chain(&b).copied().collect();
    points.sort_by(f64::total_cmp);
    let cdf = |s: &[f64], x: f64| s.partition_point(|v| *v <= x) as f64 / s.len() as f64;
    points.windows(2).map(|w| (cdf(&a, w[0]) - cdf(&b, w[0])).abs() * (w[1] - w[0])).sum()
}

/// The Gaussian kernel over pooled points, with the median-heuristic bandwidth.
pub struct Kernel {
    k: Vec<f64>,
    n: usize,
    pub bandwidth: f64,
}

impl Kernel {
    pub fn new(points: &[Vec<f32>]) -> Kernel {
        let n = points.len();
        let mut d2 = vec![0f64; n * n];
        for i in 0..n {
            for j in i + 1..n {
                let d: f64 = points[i].iter().zip(&points[j]).map(|(x, y)| ((x - y) as f64).powi(2)).sum();
                d2[i * n + j] = d;
                d2[j * n + i] = d;
            }
        }
        let mut off: Vec<f64> =
            (0..n).flat_map(|i| (i + 1..n).map(move |j| (i, j))).map(|(i, j)| d2[i * n + j]).collect();
        off.sort_by(f64::total_cmp);
        let median = off.get(off.len() / 2).copied().unwrap_or(1.0).sqrt();
        let bandwidth = if median > 1e-9 { median } else { 1.0 };
        let k = d2.iter().map(|d| (-d / (2.0 * bandwidth * bandwidth)).exp()).collect();
        Kernel { k, n, bandwidth }
    }

    /// Unbiased squared MMD between the pooled points at indexes `a` and at `b`. Repeats
    /// are allowed, as a bootstrap draws them; a point is never paired with a copy of
    /// itself within a sample (that pair would count as two identical draws).
    pub fn mmd2(&self, a: &[usize], b: &[usize]) -> f64 {
        let k = |i: usize, j: usize| self.k[i * self.n + j];
        let within = |s: &[usize]| {
            let m = s.len();
            if m < 2 {
                return 0.0;
            }
            let (mut sum, mut pairs) = (0.0, 0usize);
            for &i in s {
                for &j in s {
                    if i != j {
                        sum += k(i, j);
                        pairs += 1;
                    }
                }
            }
            if pairs == 0 { 0.0 } else { sum / pairs as f64 }
        };
        let mut cross = 0.0;
        for &i in a {
            for &j in b {
                cross += k(i, j);
            }
        }
        within(a) + within(b) - 2.0 * cross / (a.len().max(1) * b.len().max(1)) as f64
    }
}

/// The Fréchet distance of the Gaussians fitted to `a` and `b` (rows are points).
pub fn frechet(a: &[&[f32]], b: &[&[f32]]) -> f64 {
    if a.len() < 2 || b.len() < 2 {
        return f64::NAN;
    }
    let d = a[0].len();
    let centred = |s: &[&[f32]]| {
        let n = s.len();
        let mut mean = vec![0f64; d];
        for p in s {
            for (m, x) in mean.iter_mut().zip(p.iter()) {
                *m += *x as f64 / n as f64;
            }
        }
        let scale = 1.0 / ((n - 1) as f64).sqrt();
        let m = nalgebra::DMatrix::from_fn(d, n, |i, j| (s[j][i] as f64 - mean[i]) * scale);
        (mean, m)
    };
    let (ma, a) = centred(a);
    let (mb, b) = centred(b);
    let mean: f64 = ma.iter().zip(&mb).map(|(x, y)| (x - y).powi(2)).sum();
    let trace = |m: &nalgebra::DMatrix<f64>| m.iter().map(|x| x * x).sum::<f64>();
    let cross = a.transpose() * &b;
    // the singular values of AᵀB: square roots of the eigenvalues of the smaller Gram matrix
    let gram = if cross.nrows() <= cross.ncols() { &cross * cross.transpose() } else { cross.transpose() * &cross };
    let nuclear: f64 = gram.symmetric_eigenvalues().iter().map(|l| l.max(0.0).sqrt()).sum();
    (mean + trace(&a) + trace(&b) - 2.0 * nuclear).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn h(pairs: &[(&str, u32)]) -> BTreeMap<String, u32> {
        pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    #[test]
    fn jsd_bounds() {
        assert_eq!(jsd(&h(&[("a", 3), ("b", 1)]), &h(&[("a", 6), ("b", 2)])), 0.0);
        assert!((jsd(&h(&[("a", 1)]), &h(&[("b", 1)])) - 1.0).abs() < 1e-12);
        // p = (1/2, 1/2), q = (1, 0): 0.5·KL(p‖m) + 0.5·KL(q‖m), m = (3/4, 1/4)
        let expected =
            0.5 * (0.5 * (0.5f64 / 0.75).log2() + 0.5 * (0.5f64 / 0.25).log2()) + 0.5 * (1.0f64 / 0.75).log2();
        assert!((jsd(&h(&[("a", 1), ("b", 1)]), &h(&[("a", 1)])) - expected).abs() < 1e-12);
    }

    #[test]
    fn wasserstein_shift() {
        assert!((wasserstein1(&[1.0, 2.0, 3.0], &[2.0, 3.0, 4.0]) - 1.0).abs() < 1e-12);
        assert_eq!(wasserstein1(&[2.0, 2.0], &[2.0]), 0.0);
        assert!((wasserstein1(&[0.0], &[0.0, 10.0]) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn frechet_of_shifted_gaussians() {
        // the same points shifted by (3, 4): the covariance terms cancel, 25 remains
        let a: Vec<Vec<f32>> = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![0.0, 2.0], vec![1.0, 1.0], vec![2.0, 1.0]];
        let b: Vec<Vec<f32>> = a.iter().map(|p| vec![p[0] + 3.0, p[1] + 4.0]).collect();
        let ra: Vec<&[f32]> = a.iter().map(|p| p.as_slice()).collect();
        let rb: Vec<&[f32]> = b.iter().map(|p| p.as_slice()).collect();
        assert!((frechet(&ra, &rb) - 25.0).abs() < 1e-6, "{}", frechet(&ra, &rb));
        assert!(frechet(&ra, &ra).abs() < 1e-6);
        // scaled by 2 around the same mean: tr Σ + tr 4Σ − 2 tr 2Σ = tr Σ
        let c: Vec<Vec<f32>> = a.iter().map(|p| vec![p[0] * 2.0 - 0.8, p[1] * 2.0 - 0.8]).collect();
        let rc: Vec<&[f32]> = c.iter().map(|p| p.as_slice()).collect();
        let mean = [0.8f64, 0.8];
        let var: f64 =
            a.iter().map(|p| (p[0] as f64 - mean[0]).powi(2) + (p[1] as f64 - mean[1]).powi(2)).sum::<f64>() / 4.0;
        assert!((frechet(&ra, &rc) - var).abs() < 1e-4, "{} vs {var}", frechet(&ra, &rc));
    }

    #[test]
    fn mmd_near_zero_for_one_sample_and_positive_for_two() {
        let points: Vec<Vec<f32>> =
            (0..40).map(|i| vec![(i % 20) as f32 * 0.1, if i < 20 { 0.0 } else { 5.0 }]).collect();
        let k = Kernel::new(&points);
        let first: Vec<usize> = (0..20).collect();
        let second: Vec<usize> = (20..40).collect();
        let evens: Vec<usize> = (0..40).step_by(2).collect();
        let odds: Vec<usize> = (1..40).step_by(2).collect();
        assert!(k.mmd2(&first, &second) > 0.5);
        assert!(k.mmd2(&evens, &odds).abs() < 0.1);
    }
}
