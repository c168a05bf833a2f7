//! Matrix products for learning: `C ← C + A·B` in `f32`, each output one chain of fused
//! multiply-adds over `k` in ascending order, started from the value `C` holds (zero, or a
//! bias). The kernels vectorise across outputs only, never across `k`, so AVX-512 (16
//! lanes), AVX2 (8) and the scalar fallback (`f32::mul_add`), and any split of the outputs
//! between threads, give the same bits: a trained file depends neither on the machine's
//! vector width nor on its core count (`every_kernel_gives_the_reference_bits`).
//!
//! The operands are strided views, so `x·Wᵀ`, `g·W` and `gᵀ·x` need no transposed copies.
//! `B` is packed in panels of `NR` columns, `k` in steps of [`KC`] so that a panel stays
//! in L1 (a row-major `B` is copied row by row, a transposed one in 8 × 8 blocks); `A` is
//! read in place, `MR` rows at a time (a short last panel repeats its last row, whose
//! outputs are not kept). The micro-kernel holds an `MR × NR` tile of `C` in registers.
//! A product big enough to share is cut into bands of rows, one per thread of rayon's pool.

use std::cell::RefCell;
use std::sync::OnceLock;

use rayon::prelude::*;

/// `k` per packed panel: a `KC × NR` panel of `B` is 32 KiB at AVX-512's `NR`.
const KC: usize = 256;

/// The most rows a kernel takes at once.
const MR_MAX: usize = 8;

/// Multiply-adds below which a product runs on the calling thread alone.
const SHARE_FROM: usize = 1 << 20;

/// A matrix read in place: element `(r, c)` is `data[r·row_stride + c·col_stride]`.
#[derive(Clone, Copy)]
pub(crate) struct View<'a> {
    pub data: &'a [f32],
    pub rows: usize,
    pub cols: usize,
    pub row_stride: usize,
    pub col_stride: usize,
}

impl<'a> View<'a> {
    /// A row-major `rows × cols` matrix.
    pub fn rows(data: &'a [f32], rows: usize, cols: usize) -> View<'a> {
        assert!(data.len() >= rows * cols, "a {rows} × {cols} matrix in {} values", data.len());
        View { data, rows, cols, row_stride: cols, col_stride: 1 }
    }

    /// The transpose, in place.
    pub fn t(self) -> View<'a> {
        View { rows: self.cols, cols: self.rows, row_stride: self.col_stride, col_stride: self.row_stride, ..self }
    }

    #[inline]
    fn at(&self, r: usize, c: usize) -> f32 {
        self.data[r * self.row_stride + c * self.col_stride]
    }

    /// Rows `from..to`.
    fn band(self, from: usize, to: usize) -> View<'a> {
        let start = (from * self.row_stride).min(self.data.len());
        View { data: &self.data[start..], rows: to - from, ..self }
    }
}

/// `MR` rows of `A` from `q = 0`: each row's offset into the data, and the step along `k`.
struct Rows<'a> {
    data: &'a [f32],
    at: [usize; MR_MAX],
    step: usize,
}

/// A micro-kernel: the `MR × NR` tile of `c` (rows `ldc` apart) += rows `a` times the
/// packed panel `b`, over `k` steps.
#[derive(Clone, Copy)]
struct Kernel {
    mr: usize,
    nr: usize,
    run: fn(k: usize, a: &Rows, b: &[f32], c: &mut [f32], ldc: usize),
    name: &'static str,
}

impl Kernel {
    fn detect() -> Kernel {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                return x86::AVX512;
            }
            if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
                return x86::AVX2;
            }
        }
        SCALAR
    }

    fn best() -> Kernel {
        static BEST: OnceLock<Kernel> = OnceLock::new();
        *BEST.get_or_init(Kernel::detect)
    }
}

/// The name of the kernel this machine runs ("avx512", "avx2", "scalar").
pub fn kernel_name() -> &'static str {
    Kernel::best().name
}

/// `c ← c + a·b`, `c` row-major `a.rows × b.cols`.
pub(crate) fn gemm(a: View, b: View, c: &mut [f32]) {
    gemm_with(Kernel::best(), a, b, c, rayon::current_num_threads());
}

fn gemm_with(kernel: Kernel, a: View, b: View, c: &mut [f32], threads: usize) {
    let (m, n) = (a.rows, b.cols);
    assert_eq!(a.cols, b.rows, "the inner dimensions agree");
    assert_eq!(c.len(), m * n, "the output holds a.rows × b.cols");
    if m == 0 || n == 0 {
        return;
    }
    let panels = m.div_ceil(kernel.mr);
    let bands = if m * n * a.cols < SHARE_FROM { 1 } else { threads.clamp(1, panels) };
    if bands == 1 {
        return band(kernel, a, b, c);
    }
    // whole panels per band, as even as they go
    let per = panels.div_ceil(bands) * kernel.mr;
    c.par_chunks_mut(per * n).enumerate().for_each(|(i, c)| {
        let from = i * per;
        band(kernel, a.band(from, (from + per).min(m)), b, c);
    });
}

thread_local! {
    static PACK: RefCell<Vec<f32>> = const { RefCell::new(Vec::new()) };
}

/// One band of rows: `k` in steps of `KC`; each `B` panel packed once and run against
/// every `MR` rows of `A`.
fn band(kernel: Kernel, a: View, b: View, c: &mut [f32]) {
    let Kernel { mr, nr, run, .. } = kernel;
    let (m, k, n) = (a.rows, a.cols, b.cols);
    PACK.with_borrow_mut(|panel| {
        let mut tile = [0.0f32; 8 * 32];
        for k0 in (0..k).step_by(KC) {
            let kc = KC.min(k - k0);
            for j0 in (0..n).step_by(nr) {
                let cols = nr.min(n - j0);
                pack_b(b, k0, kc, j0, nr, panel);
                for i0 in (0..m).step_by(mr) {
                    let rows = mr.min(m - i0);
                    let mut at = [0; MR_MAX];
                    for (r, at) in at.iter_mut().enumerate().take(mr) {
                        *at = (i0 + r.min(rows - 1)) * a.row_stride + k0 * a.col_stride;
                    }
                    let a_rows = Rows { data: a.data, at, step: a.col_stride };
                    let b_panel = &panel[..kc * nr];
                    if rows == mr && cols == nr {
                        run(kc, &a_rows, b_panel, &mut c[i0 * n + j0..], n);
                        continue;
                    }
                    // a tile at an edge: through a copy
                    for r in 0..rows {
                        let from = (i0 + r) * n + j0;
                        tile[r * nr..r * nr + cols].copy_from_slice(&c[from..from + cols]);
                    }
                    run(kc, &a_rows, b_panel, &mut tile, nr);
                    for r in 0..rows {
                        let from = (i0 + r) * n + j0;
                        c[from..from + cols].copy_from_slice(&tile[r * nr..r * nr + cols]);
                    }
                }
            }
        }
    });
}

/// Columns `j0..j0 + nr` of `B`'s rows `k0..k0 + kc`, `nr` values a step (zeros past the
/// last column).
fn pack_b(b: View, k0: usize, kc: usize, j0: usize, nr: usize, out: &mut Vec<f32>) {
    out.clear();
    out.resize(kc * nr, 0.0);
    let cols = nr.min(b.cols - j0);
    if b.col_stride == 1 {
        // element by element: a call to memmove per 32 values would cost more than the copy
        for (q, row) in out.chunks_exact_mut(nr).enumerate() {
            let from = (k0 + q) * b.row_stride + j0;
            row[..cols].iter_mut().zip(&b.data[from..from + cols]).for_each(|(o, v)| *o = *v);
        }
    } else if b.row_stride == 1 {
        // column c of the panel is a row of the data: transposed in 8 × 8 blocks
        let (whole_c, whole_q) = (cols / 8 * 8, kc / 8 * 8);
        for c in (0..whole_c).step_by(8) {
            for q in (0..whole_q).step_by(8) {
                let from = (j0 + c) * b.col_stride + k0 + q;
                transpose8(&b.data[from..], b.col_stride, &mut out[q * nr + c..], nr);
            }
        }
        for c in 0..cols {
            let q_from = if c < whole_c { whole_q } else { 0 };
            for q in q_from..kc {
                out[q * nr + c] = b.at(k0 + q, j0 + c);
            }
        }
    } else {
        for q in 0..kc {
            for c in 0..cols {
                out[q * nr + c] = b.at(k0 + q, j0 + c);
            }
        }
    }
}

/// `out[q·ld_out + c] = data[c·ld + q]` for an 8 × 8 block.
fn transpose8(data: &[f32], ld: usize, out: &mut [f32], ld_out: usize) {
    assert!(data.len() > 7 * ld + 7 && out.len() > 7 * ld_out + 7);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: AVX was detected; the bounds above cover every load and store
        return unsafe { x86::transpose8(data.as_ptr(), ld, out.as_mut_ptr(), ld_out) };
    }
    for c in 0..8 {
        for q in 0..8 {
            out[q * ld_out + c] = data[c * ld + q];
        }
    }
}

/// The portable kernel: one `mul_add` chain per output, as the vector kernels compute it.
const SCALAR: Kernel = Kernel { mr: 4, nr: 4, run: scalar, name: "scalar" };

fn scalar(k: usize, a: &Rows, b: &[f32], c: &mut [f32], ldc: usize) {
    const MR: usize = 4;
    const NR: usize = 4;
    for q in 0..k {
        for r in 0..MR {
            let x = a.data[a.at[r] + q * a.step];
            for j in 0..NR {
                c[r * ldc + j] = x.mul_add(b[q * NR + j], c[r * ldc + j]);
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{Kernel, Rows};

    pub(super) const AVX512: Kernel = Kernel { mr: 8, nr: 32, run: avx512_safe, name: "avx512" };
    pub(super) const AVX2: Kernel = Kernel { mr: 6, nr: 16, run: avx2_safe, name: "avx2" };

    /// Every value the kernel reads is inside its operands.
    fn check(k: usize, a: &Rows, mr: usize, b: &[f32], nr: usize, c: &[f32], ldc: usize) {
        let last = k.saturating_sub(1) * a.step;
        assert!(a.at[..mr].iter().all(|&at| k == 0 || at + last < a.data.len()));
        assert!(b.len() >= k * nr && ldc >= nr && c.len() >= (mr - 1) * ldc + nr);
    }

    /// Only chosen by [`Kernel::detect`] when the CPU has AVX-512F.
    fn avx512_safe(k: usize, a: &Rows, b: &[f32], c: &mut [f32], ldc: usize) {
        check(k, a, 8, b, 32, c, ldc);
        // SAFETY: the feature was detected before this kernel was chosen; `check` covers
        // every load and store
        unsafe { avx512(k, a, b, c, ldc) }
    }

    #[target_feature(enable = "avx512f")]
    unsafe fn avx512(k: usize, a: &Rows, b: &[f32], c: &mut [f32], ldc: usize) {
        const MR: usize = 8;
        const NR: usize = 32;
        let (base, b, t) = (a.data.as_ptr(), b.as_ptr(), c.as_mut_ptr());
        // SAFETY (every pointer below): within the bounds `check` asserted
        unsafe {
            let mut rows = [base; MR];
            for (r, p) in rows.iter_mut().enumerate() {
                *p = base.add(a.at[r]);
            }
            let mut acc = [[_mm512_setzero_ps(); 2]; MR];
            for (r, row) in acc.iter_mut().enumerate() {
                row[0] = _mm512_loadu_ps(t.add(r * ldc));
                row[1] = _mm512_loadu_ps(t.add(r * ldc + 16));
            }
            for q in 0..k {
                let b0 = _mm512_loadu_ps(b.add(q * NR));
                let b1 = _mm512_loadu_ps(b.add(q * NR + 16));
                for (row, p) in acc.iter_mut().zip(&rows) {
                    let x = _mm512_set1_ps(*p.add(q * a.step));
                    row[0] = _mm512_fmadd_ps(x, b0, row[0]);
                    row[1] = _mm512_fmadd_ps(x, b1, row[1]);
                }
            }
            for (r, row) in acc.iter().enumerate() {
                _mm512_storeu_ps(t.add(r * ldc), row[0]);
                _mm512_storeu_ps(t.add(r * ldc + 16), row[1]);
            }
        }
    }

    /// Only chosen by [`Kernel::detect`] when the CPU has AVX2 and FMA.
    fn avx2_safe(k: usize, a: &Rows, b: &[f32], c: &mut [f32], ldc: usize) {
        check(k, a, 6, b, 16, c, ldc);
        // SAFETY: the features were detected before this kernel was chosen; `check`
        // covers every load and store
        unsafe { avx2(k, a, b, c, ldc) }
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn avx2(k: usize, a: &Rows, b: &[f32], c: &mut [f32], ldc: usize) {
        const MR: usize = 6;
        const NR: usize = 16;
        let (base, b, t) = (a.data.as_ptr(), b.as_ptr(), c.as_mut_ptr());
        // SAFETY (every pointer below): within the bounds `check` asserted
        unsafe {
            let mut rows = [base; MR];
            for (r, p) in rows.iter_mut().enumerate() {
                *p = base.add(a.at[r]);
            }
            let mut acc = [[_mm256_setzero_ps(); 2]; MR];
            for (r, row) in acc.iter_mut().enumerate() {
                row[0] = _mm256_loadu_ps(t.add(r * ldc));
                row[1] = _mm256_loadu_ps(t.add(r * ldc + 8));
            }
            for q in 0..k {
                let b0 = _mm256_loadu_ps(b.add(q * NR));
                let b1 = _mm256_loadu_ps(b.add(q * NR + 8));
                for (row, p) in acc.iter_mut().zip(&rows) {
                    let x = _mm256_set1_ps(*p.add(q * a.step));
                    row[0] = _mm256_fmadd_ps(x, b0, row[0]);
                    row[1] = _mm256_fmadd_ps(x, b1, row[1]);
                }
            }
            for (r, row) in acc.iter().enumerate() {
                _mm256_storeu_ps(t.add(r * ldc), row[0]);
                _mm256_storeu_ps(t.add(r * ldc + 8), row[1]);
            }
        }
    }

    /// An 8 × 8 transpose in registers (unpack, shuffle, swap halves).
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn transpose8(data: *const f32, ld: usize, out: *mut f32, ld_out: usize) {
        // SAFETY: the caller checked that 8 rows of 8 lie inside `data` and `out`
        unsafe {
            let r: [__m256; 8] = std::array::from_fn(|c| _mm256_loadu_ps(data.add(c * ld)));
            let t0 = _mm256_unpacklo_ps(r[0], r[1]);
            let t1 = _mm256_unpackhi_ps(r[0], r[1]);
            let t2 = _mm256_unpacklo_ps(r[2], r[3]);
            let t3 = _mm256_unpackhi_ps(r[2], r[3]);
            let t4 = _mm256_unpacklo_ps(r[4], r[5]);
            let t5 = _mm256_unpackhi_ps(r[4], r[5]);
            let t6 = _mm256_unpacklo_ps(r[6], r[7]);
            let t7 = _mm256_unpackhi_ps(r[6], r[7]);
            let s0 = _mm256_shuffle_ps::<0x44>(t0, t2);
            let s1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
            let s2 = _mm256_shuffle_ps::<0x44>(t1, t3);
            let s3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
            let s4 = _mm256_shuffle_ps::<0x44>(t4, t6);
            let s5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
            let s6 = _mm256_shuffle_ps::<0x44>(t5, t7);
            let s7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
            let rows = [
                _mm256_permute2f128_ps::<0x20>(s0, s4),
                _mm256_permute2f128_ps::<0x20>(s1, s5),
                _mm256_permute2f128_ps::<0x20>(s2, s6),
                _mm256_permute2f128_ps::<0x20>(s3, s7),
                _mm256_permute2f128_ps::<0x31>(s0, s4),
                _mm256_permute2f128_ps::<0x31>(s1, s5),
                _mm256_permute2f128_ps::<0x31>(s2, s6),
                _mm256_permute2f128_ps::<0x31>(s3, s7),
            ];
            for (q, row) in rows.iter().enumerate() {
                _mm256_storeu_ps(out.add(q * ld_out), *row);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tad_ir::{Rng, SplitMix64};

    /// Each output's chain as written: from its start value, `k` ascending, fused.
    fn reference(a: View, b: View, c: &mut [f32]) {
        for i in 0..a.rows {
            for j in 0..b.cols {
                let mut acc = c[i * b.cols + j];
                for q in 0..a.cols {
                    acc = a.at(i, q).mul_add(b.at(q, j), acc);
                }
                c[i * b.cols + j] = acc;
            }
        }
    }

    fn kernels() -> Vec<Kernel> {
        let mut out = vec![SCALAR];
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
                out.push(x86::AVX2);
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                out.push(x86::AVX512);
            }
        }
        out
    }

    fn bits(x: &[f32]) -> Vec<u32> {
        x.iter().map(|v| v.to_bits()).collect()
    }

    #[test]
    fn every_kernel_gives_the_reference_bits() {
        let mut rng = SplitMix64::new(5);
        let mut draw = |n: usize| -> Vec<f32> { (0..n).map(|_| (rng.unit() as f32 - 0.5) * 3.0).collect() };
        // odd edges, a k past one KC step, a band split across threads
        for (m, k, n) in [(1, 1, 1), (7, 3, 5), (13, 300, 33), (37, 17, 70), (256, 64, 40), (130, 520, 19)] {
            let (a, b, start) = (draw(m * k), draw(k * n), draw(m * n));
            // a plain product, through transposed views, and mixed
            let cases: [(View, View); 3] = [
                (View::rows(&a, m, k), View::rows(&b, k, n)),
                (View::rows(&a, k, m).t(), View::rows(&b, n, k).t()),
                (View::rows(&a, m, k), View::rows(&b, n, k).t()),
            ];
            for (i, (va, vb)) in cases.into_iter().enumerate() {
                let mut expected = start.clone();
                reference(va, vb, &mut expected);
                for kernel in kernels() {
                    for threads in [1, 2, 3] {
                        let mut c = start.clone();
                        gemm_with(kernel, va, vb, &mut c, threads);
                        assert_eq!(
                            bits(&c),
                            bits(&expected),
                            "{} on {m}×{k}·{k}×{n}, case {i}, {threads} threads",
                            kernel.name
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn the_block_transpose_is_the_plain_one() {
        let data: Vec<f32> = (0..11 * 9).map(|v| v as f32).collect();
        let mut out = vec![0.0; 8 * 10];
        transpose8(&data[3..], 11, &mut out, 10);
        for c in 0..8 {
            for q in 0..8 {
                assert_eq!(out[q * 10 + c], data[3 + c * 11 + q]);
            }
        }
    }
}
