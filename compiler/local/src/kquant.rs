//! The quantized formats of Qwen2.5-Coder's Q4_K_M files beside [`crate::quant`]'s: Q5_0
//! (32 values a block, 5 bits) and ggml's super-blocks of 256 values, Q4_K (eight
//! sub-blocks of 32, each with a 6-bit scale and minimum) and Q6_K (sixteen sub-blocks of 16,
//! each with an 8-bit scale).
//!
//! Q5_0 takes the activations the other 32-value formats take ([`Q8_1`]). The K formats
//! take theirs as llama.cpp does, a super-block at a time ([`Q8K`]: one scale for 256
//! values, and the sum of every 16 of them). A super-block's product is then one integer
//! sum, with each sub-block's scale applied as an integer: a Q4_K minimum meets the
//! activations' sums of 16, and Q6_K's offset of 32 is taken off the same way, so its
//! values go into the multiply unsigned. The floats enter once per 256 values.
//! The scalar kernels unpack a block's small integers and sum; the AVX2 ones do the same on
//! the packed bytes, 32 values a step. For the K formats the two are the same integers
//! scaled in the same order, so they give the same bits; for Q5_0 they differ in the order
//! of the float additions.
//!
//! The layouts are ggml's (`ggml-common.h`, `block_q5_0`, `block_q4_K`, `block_q6_K`,
//! `block_q8_K`); the tests hold the dequantization to candle's on random blocks and on the
//! real files.

use crate::quant::{BLOCK, FormatKernels, Q8_1, f16_to_f32};

/// Values in a super-block.
pub const SUPER: usize = 256;

/// `d·(q − 16)`, q in 0..32: the low four bits in `qs` (value `j` in the low nibble of
/// byte `j`, value `j + 16` in its high nibble), the fifth bit of value `j` in bit `j` of `qh`.
#[derive(Clone, Copy, Debug)]
pub struct Q5_0 {
    pub d: f32,
    pub qh: u32,
    pub qs: [u8; 16],
}

/// `d·sc_b·q − dmin·m_b` for sub-block `b = position / 32`, q in 0..16.
#[derive(Clone, Copy, Debug)]
pub struct Q4K {
    pub d: f32,
    pub dmin: f32,
    /// The eight 6-bit scales and the eight 6-bit minima, unpacked once when the file is
    /// read (the file packs them into 12 bytes: [`scale_min`]), not at every product.
    pub scales: [u8; 8],
    pub mins: [u8; 8],
    /// Per 64 values: the first 32 in the low nibbles of 32 bytes, the next 32 in their
    /// high nibbles.
    pub qs: [u8; 128],
}

/// Activations for the K formats: `d·q` over 256 values, q in −127..=127, and `bsums[j]`
/// the sum of the `q` of values `16j..16j + 16`.
#[derive(Clone, Copy, Debug)]
pub struct Q8K {
    pub d: f32,
    pub qs: [i8; SUPER],
    pub bsums: [i16; 16],
}

impl Default for Q8K {
    fn default() -> Self {
        Q8K { d: 0.0, qs: [0; SUPER], bsums: [0; 16] }
    }
}

/// Quantizes `x` into `out`, a super-block per 256 values (a shorter tail is left out: the
/// K formats' rows are whole super-blocks). As ggml's `quantize_row_q8_K`, the value of
/// largest magnitude goes to −127 and the rest round to nearest, ties to even.
pub fn quantize_k(x: &[f32], out: &mut Vec<Q8K>) {
    out.clear();
    for chunk in x.chunks_exact(SUPER) {
        let max = chunk.iter().fold(0f32, |m, &v| if v.abs() > m.abs() { v } else { m });
        let mut block = Q8K::default();
        if max != 0.0 && max.is_finite() {
            let inverse = -127.0 / max;
            for (q, &v) in block.qs.iter_mut().zip(chunk) {
                *q = nearest_even(inverse * v).min(127.0) as i8;
            }
            for (sum, q) in block.bsums.iter_mut().zip(block.qs.chunks_exact(16)) {
                *sum = q.iter().map(|&q| q as i16).sum();
            }
            block.d = 1.0 / inverse;
        }
        out.push(block);
    }
}

/// `x` rounded to the nearest integer, ties to even, for |x| ≤ 2²²: adding and taking off
/// 1.5·2²³ leaves no bits below the unit, rounded as the FPU rounds (to nearest, ties to
/// even); a zero may lose its sign. `f32::round_ties_even` is a call into libm on a CPU
/// baseline without SSE4.1.
fn nearest_even(x: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0;
    (x + MAGIC) - MAGIC
}

/// `d·sc_b·(q − 32)` for sub-block `b = position / 16`, q in 0..64: four bits in `ql`, two in `qh`.
#[derive(Clone, Copy, Debug)]
pub struct Q6K {
    pub ql: [u8; 128],
    pub qh: [u8; 64],
    pub scales: [i8; 16],
    pub d: f32,
}

fn half(b: &[u8], at: usize) -> f32 {
    f16_to_f32(u16::from_le_bytes([b[at], b[at + 1]]))
}

/// Q5_0 blocks from a GGUF tensor's bytes (22 bytes a block: d as f16, qh, qs).
pub fn read_q5_0(bytes: &[u8]) -> Vec<Q5_0> {
    bytes
        .chunks_exact(22)
        .map(|b| Q5_0 {
            d: half(b, 0),
            qh: u32::from_le_bytes([b[2], b[3], b[4], b[5]]),
            qs: b[6..22].try_into().unwrap_or([0; 16]),
        })
        .collect()
}

/// Q4_K super-blocks (144 bytes: d, dmin as f16, 12 bytes of scales, 128 of values).
pub fn read_q4_k(bytes: &[u8]) -> Vec<Q4K> {
    bytes
        .chunks_exact(144)
        .map(|b| {
            let packed: [u8; 12] = b[4..16].try_into().unwrap_or([0; 12]);
            let (mut scales, mut mins) = ([0; 8], [0; 8]);
            for j in 0..8 {
                (scales[j], mins[j]) = scale_min(&packed, j);
            }
            Q4K { d: half(b, 0), dmin: half(b, 2), scales, mins, qs: b[16..144].try_into().unwrap_or([0; 128]) }
        })
        .collect()
}

/// Q6_K super-blocks (210 bytes: ql, qh, 16 signed scales, d as f16).
pub fn read_q6_k(bytes: &[u8]) -> Vec<Q6K> {
    bytes
        .chunks_exact(210)
        .map(|b| {
            let mut scales = [0i8; 16];
            for (s, &byte) in scales.iter_mut().zip(&b[192..208]) {
                *s = byte as i8;
            }
            Q6K {
                ql: b[0..128].try_into().unwrap_or([0; 128]),
                qh: b[128..192].try_into().unwrap_or([0; 64]),
                scales,
                d: half(b, 208),
            }
        })
        .collect()
}

impl Q5_0 {
    /// The block's values as integers `q − 16`.
    fn values(&self) -> [i8; BLOCK] {
        let mut q = [0i8; BLOCK];
        for j in 0..16 {
            let (lo, hi) = (self.qs[j] & 0x0f, self.qs[j] >> 4);
            let (b0, b1) = (((self.qh >> j) & 1) as u8, ((self.qh >> (j + 16)) & 1) as u8);
            q[j] = (lo | b0 << 4) as i8 - 16;
            q[j + 16] = (hi | b1 << 4) as i8 - 16;
        }
        q
    }
}

/// Sub-block `j`'s 6-bit scale and minimum in a Q4_K's 12 packed bytes (ggml's
/// `get_scale_min_k4`).
fn scale_min(q: &[u8; 12], j: usize) -> (u8, u8) {
    if j < 4 {
        (q[j] & 63, q[j + 4] & 63)
    } else {
        ((q[j + 4] & 0x0f) | ((q[j - 4] >> 6) << 4), (q[j + 4] >> 4) | ((q[j] >> 6) << 4))
    }
}

impl Q4K {
    /// The 256 values as integers in 0..16, in order.
    fn values(&self) -> [u8; SUPER] {
        let mut q = [0u8; SUPER];
        for c in 0..4 {
            for l in 0..32 {
                let byte = self.qs[32 * c + l];
                q[64 * c + l] = byte & 0x0f;
                q[64 * c + 32 + l] = byte >> 4;
            }
        }
        q
    }
}

impl Q6K {
    /// The 256 values as integers `q − 32`, in order.
    fn values(&self) -> [i8; SUPER] {
        let mut q = [0i8; SUPER];
        for n in 0..2 {
            let (ql, qh) = (&self.ql[64 * n..64 * n + 64], &self.qh[32 * n..32 * n + 32]);
            let y = &mut q[128 * n..128 * n + 128];
            for l in 0..32 {
                y[l] = ((ql[l] & 0x0f) | ((qh[l] & 3) << 4)) as i8 - 32;
                y[l + 32] = ((ql[l + 32] & 0x0f) | (((qh[l] >> 2) & 3) << 4)) as i8 - 32;
                y[l + 64] = ((ql[l] >> 4) | (((qh[l] >> 4) & 3) << 4)) as i8 - 32;
                y[l + 96] = ((ql[l + 32] >> 4) | (((qh[l] >> 6) & 3) << 4)) as i8 - 32;
            }
        }
        q
    }
}

/// The values of Q5_0 blocks, in order.
pub fn dequantize_q5_0(blocks: &[Q5_0], out: &mut Vec<f32>) {
    out.clear();
    for b in blocks {
        out.extend(b.values().iter().map(|&q| q as f32 * b.d));
    }
}

/// The values of Q4_K super-blocks, in order (`d·sc` and `dmin·m` formed first, as ggml does).
pub fn dequantize_q4_k(blocks: &[Q4K], out: &mut Vec<f32>) {
    out.clear();
    for b in blocks {
        let q = b.values();
        for (sub, chunk) in q.chunks_exact(BLOCK).enumerate() {
            let (sc, m) = (b.scales[sub], b.mins[sub]);
            let (scale, min) = (b.d * sc as f32, b.dmin * m as f32);
            out.extend(chunk.iter().map(|&v| scale * v as f32 - min));
        }
    }
}

/// The values of Q6_K super-blocks, in order.
pub fn dequantize_q6_k(blocks: &[Q6K], out: &mut Vec<f32>) {
    out.clear();
    for b in blocks {
        let q = b.values();
        for (sub, chunk) in q.chunks_exact(16).enumerate() {
            let scale = b.d * b.scales[sub] as f32;
            out.extend(chunk.iter().map(|&v| scale * v as f32));
        }
    }
}

/// The integer dot product of two runs of small integers.
fn isum<A: Copy + Into<i32>>(a: &[A], b: &[i8]) -> i32 {
    a.iter().zip(b).map(|(&a, &b)| a.into() * b as i32).sum()
}

/// Q5_0 blocks against as many activation blocks: Σ d·dx·Σq·x.
pub fn dot_q5_0(w: &[Q5_0], x: &[Q8_1]) -> f32 {
    w.iter().zip(x).map(|(b, x)| b.d * x.d * isum(&b.values(), &x.qs) as f32).sum()
}

/// Q4_K super-blocks against as many activation super-blocks: per super-block
/// `d·dx·Σ sc·Σq·x − dmin·dx·Σ m·Σx` (a minimum meets its sub-block's two sums of 16).
pub fn dot_q4_k(w: &[Q4K], x: &[Q8K]) -> f32 {
    let mut total = 0.0;
    for (b, x) in w.iter().zip(x) {
        let (q, scales, mins) = (b.values(), b.scales, b.mins);
        let (mut sum, mut min) = (0i32, 0i32);
        for sub in 0..SUPER / BLOCK {
            let at = BLOCK * sub..BLOCK * (sub + 1);
            sum += scales[sub] as i32 * isum(&q[at.clone()], &x.qs[at]);
            min += mins[sub] as i32 * (x.bsums[2 * sub] as i32 + x.bsums[2 * sub + 1] as i32);
        }
        total += b.d * x.d * sum as f32 - b.dmin * x.d * min as f32;
    }
    total
}

/// Q6_K super-blocks against as many activation super-blocks: `d·dx·Σ sc·Σq·x` per 16 values.
pub fn dot_q6_k(w: &[Q6K], x: &[Q8K]) -> f32 {
    let mut total = 0.0;
    for (b, x) in w.iter().zip(x) {
        let q = b.values();
        let sum: i32 = (0..16)
            .map(|sub| b.scales[sub] as i32 * isum(&q[16 * sub..16 * sub + 16], &x.qs[16 * sub..16 * sub + 16]))
            .sum();
        total += b.d * x.d * sum as f32;
    }
    total
}

/// The three formats' kernels.
pub type Formats = (FormatKernels<Q5_0>, FormatKernels<Q4K, Q8K>, FormatKernels<Q6K, Q8K>);

/// The AVX2 kernels; only for a CPU [`crate::quant::Kernels::detect`] found them on.
#[cfg(target_arch = "x86_64")]
pub(crate) fn avx2_kernels() -> Formats {
    (
        FormatKernels { one: |w, x| avx2::q5_0_safe(w, [x])[0], four: avx2::q5_0_safe },
        FormatKernels { one: |w, x| avx2::q4_k_safe(w, [x])[0], four: avx2::q4_k_safe },
        FormatKernels { one: |w, x| avx2::q6_k_safe(w, [x])[0], four: avx2::q6_k_safe },
    )
}

pub fn scalar_kernels() -> Formats {
    (
        FormatKernels { one: dot_q5_0, four: |w, x| x.map(|x| dot_q5_0(w, x)) },
        FormatKernels { one: dot_q4_k, four: |w, x| x.map(|x| dot_q4_k(w, x)) },
        FormatKernels { one: dot_q6_k, four: |w, x| x.map(|x| dot_q6_k(w, x)) },
    )
}

/// The same products on packed blocks, 32 values a step: a block's values as bytes, their
/// products with a token's in 16-bit pairs (`maddubs`; Q5_0's signed values through the sign
/// trick), summed to eight 32-bit lanes against 16-bit scales. Q5_0 scales and accumulates
/// the lanes in floats per block; the K formats sum them as integers over a super-block and
/// scale that as the scalar kernels do. Each block is unpacked once for all the tokens of
/// a call.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{BLOCK, Q4K, Q5_0, Q6K, Q8_1, Q8K};
    use std::arch::x86_64::*;

    pub fn q5_0_safe<const N: usize>(w: &[Q5_0], x: [&[Q8_1]; N]) -> [f32; N] {
        // SAFETY: chosen only when the CPU has AVX2 and FMA (`Kernels::detect`)
        unsafe { q5_0(w, x) }
    }

    pub fn q4_k_safe<const N: usize>(w: &[Q4K], x: [&[Q8K]; N]) -> [f32; N] {
        // SAFETY: as above
        unsafe { q4_k(w, x) }
    }

    pub fn q6_k_safe<const N: usize>(w: &[Q6K], x: [&[Q8K]; N]) -> [f32; N] {
        // SAFETY: as above
        unsafe { q6_k(w, x) }
    }

    /// `acc[t] += w·dx_t · Σ q·x_t`, `q` signed with |q| ≤ 16 (so the 16-bit pairs cannot
    /// saturate).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn add<const N: usize>(acc: &mut [__m256; N], q: __m256i, w: f32, x: [&Q8_1; N]) {
        let (magnitude, ones) = (_mm256_sign_epi8(q, q), _mm256_set1_epi16(1));
        for (acc, x) in acc.iter_mut().zip(x) {
            // SAFETY: 32 bytes, an unaligned load
            let xq = unsafe { _mm256_loadu_si256(x.qs.as_ptr().cast()) };
            let pairs = _mm256_maddubs_epi16(magnitude, _mm256_sign_epi8(xq, q));
            let sums = _mm256_madd_epi16(pairs, ones);
            *acc = _mm256_fmadd_ps(_mm256_set1_ps(w * x.d), _mm256_cvtepi32_ps(sums), *acc);
        }
    }

    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn hsum(v: __m256) -> f32 {
        let v = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
        let v = _mm_add_ps(v, _mm_movehl_ps(v, v));
        let v = _mm_add_ss(v, _mm_movehdup_ps(v));
        _mm_cvtss_f32(v)
    }

    #[target_feature(enable = "avx2,fma")]
    fn q5_0<const N: usize>(w: &[Q5_0], x: [&[Q8_1]; N]) -> [f32; N] {
        // byte j of the 32 takes byte j/8 of qh, and keeps bit j%8 of it
        let spread = _mm256_set_epi64x(0x0303030303030303, 0x0202020202020202, 0x0101010101010101, 0);
        let bit = _mm256_set1_epi64x(0x8040201008040201u64 as i64);
        let (low, fifth, sixteen) = (_mm_set1_epi8(0x0f), _mm256_set1_epi8(0x10), _mm256_set1_epi8(16));
        let mut acc = [_mm256_setzero_ps(); N];
        for (i, b) in w.iter().enumerate() {
            // SAFETY: 16 bytes, an unaligned load
            let packed = unsafe { _mm_loadu_si128(b.qs.as_ptr().cast()) };
            let nibbles = _mm256_set_m128i(_mm_and_si128(_mm_srli_epi16(packed, 4), low), _mm_and_si128(packed, low));
            let bits = _mm256_and_si256(_mm256_shuffle_epi8(_mm256_set1_epi32(b.qh as i32), spread), bit);
            let high = _mm256_and_si256(_mm256_cmpeq_epi8(bits, bit), fifth);
            let q = _mm256_sub_epi8(_mm256_or_si256(nibbles, high), sixteen);
            let Some(xs) = blocks(&x, i) else { break };
            add(&mut acc, q, b.d, xs);
        }
        acc.map(|a| hsum(a))
    }

    /// Block `i` of each token's activations; `None` past the shortest.
    #[inline]
    fn blocks<'a, const N: usize>(x: &[&'a [Q8_1]; N], i: usize) -> Option<[&'a Q8_1; N]> {
        if x.iter().any(|x| i >= x.len()) {
            return None;
        }
        Some(std::array::from_fn(|t| &x[t][i]))
    }

    /// Super-blocks to go: as many as the row and every token have.
    fn supers<const N: usize>(w: usize, x: &[&[Q8K]; N]) -> usize {
        x.iter().map(|x| x.len()).fold(w, usize::min)
    }

    /// `sums += Σ maddubs(q, x)·scales`, the 32 activations at `x`.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn add_k(sums: &mut __m256i, q: __m256i, x: &[i8], scales: __m256i) {
        debug_assert!(x.len() >= 32);
        // SAFETY: 32 bytes, an unaligned load (the callers' slices are 32 long)
        let xq = unsafe { _mm256_loadu_si256(x.as_ptr().cast()) };
        *sums = _mm256_add_epi32(*sums, _mm256_madd_epi16(_mm256_maddubs_epi16(q, xq), scales));
    }

    /// The sum of eight 32-bit lanes.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn hsum_i32(v: __m256i) -> i32 {
        let v = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
        let v = _mm_add_epi32(v, _mm_shuffle_epi32(v, 0b01_00_11_10));
        let v = _mm_add_epi32(v, _mm_shuffle_epi32(v, 0b10_11_00_01));
        _mm_cvtsi128_si32(v)
    }

    /// Four tokens' sums of eight 32-bit lanes as one lane each (integers, so the order of
    /// the additions does not matter).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn hsum4_i32(v: [__m256i; 4]) -> __m128i {
        let (a, b) = (_mm256_hadd_epi32(v[0], v[1]), _mm256_hadd_epi32(v[2], v[3]));
        // token t's lanes 0..4 in lane t, its lanes 4..8 in lane t + 4
        let c = _mm256_hadd_epi32(a, b);
        _mm_add_epi32(_mm256_castsi256_si128(c), _mm256_extracti128_si256(c, 1))
    }

    /// Four tokens' activation scales, one a lane.
    #[inline]
    fn scales4<const N: usize>(x: &[&[Q8K]; N], i: usize) -> __m128 {
        let d: [f32; 4] = std::array::from_fn(|t| x[t][i].d);
        // SAFETY: 16 bytes, an unaligned load; SSE is part of x86-64
        unsafe { _mm_loadu_ps(d.as_ptr()) }
    }

    /// Four lanes' totals into the first four of `totals` (`N` is 4 where this is called).
    #[inline]
    fn store4<const N: usize>(totals: &mut [f32; N], four: __m128) {
        let mut out = [0f32; 4];
        // SAFETY: 16 bytes, an unaligned store
        unsafe { _mm_storeu_ps(out.as_mut_ptr(), four) };
        totals[..4].copy_from_slice(&out);
    }

    /// A token's sums of 16, as sixteen 16-bit lanes.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn bsums(x: &Q8K) -> __m256i {
        // SAFETY: 16 values of 2 bytes, an unaligned load
        unsafe { _mm256_loadu_si256(x.bsums.as_ptr().cast()) }
    }

    /// Each of a Q4_K's minima twice, as 16-bit lanes against the two sums of 16 of its
    /// sub-block.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn mins16(b: &Q4K) -> __m256i {
        let twice = _mm_set_epi8(7, 7, 6, 6, 5, 5, 4, 4, 3, 3, 2, 2, 1, 1, 0, 0);
        // SAFETY: 8 bytes, an unaligned load
        let mins = unsafe { _mm_loadl_epi64(b.mins.as_ptr().cast()) };
        _mm256_cvtepu8_epi16(_mm_shuffle_epi8(mins, twice))
    }

    #[target_feature(enable = "avx2,fma")]
    fn q4_k<const N: usize>(w: &[Q4K], x: [&[Q8K]; N]) -> [f32; N] {
        let low = _mm256_set1_epi8(0x0f);
        let (mut totals, mut four) = ([0f32; N], _mm_setzero_ps());
        for (i, b) in w[..supers(w.len(), &x)].iter().enumerate() {
            let (scales, mins) = (&b.scales, mins16(b));
            let mut sums = [_mm256_setzero_si256(); N];
            for pair in 0..4 {
                // SAFETY: 32 of the 128 bytes, an unaligned load
                let packed = unsafe { _mm256_loadu_si256(b.qs.as_ptr().add(32 * pair).cast()) };
                let halves = [_mm256_and_si256(packed, low), _mm256_and_si256(_mm256_srli_epi16(packed, 4), low)];
                for (h, q) in halves.into_iter().enumerate() {
                    let sub = 2 * pair + h;
                    let scale = _mm256_set1_epi16(scales[sub] as i16);
                    for (sums, x) in sums.iter_mut().zip(x) {
                        add_k(sums, q, &x[i].qs[BLOCK * sub..BLOCK * (sub + 1)], scale);
                    }
                }
            }
            if N == 4 {
                // the scalar kernel's arithmetic, a token a lane: reduced four at a time, the
                // sums cost a quarter of one token's horizontal additions
                let xd = scales4(&x, i);
                let sum = _mm_cvtepi32_ps(hsum4_i32(std::array::from_fn(|t| sums[t])));
                let min = hsum4_i32(std::array::from_fn(|t| _mm256_madd_epi16(mins, bsums(&x[t][i]))));
                let (scale, offset) = (_mm_mul_ps(_mm_set1_ps(b.d), xd), _mm_mul_ps(_mm_set1_ps(b.dmin), xd));
                four = _mm_add_ps(four, _mm_sub_ps(_mm_mul_ps(scale, sum), _mm_mul_ps(offset, _mm_cvtepi32_ps(min))));
                continue;
            }
            for ((total, sums), x) in totals.iter_mut().zip(sums).zip(x) {
                let x = &x[i];
                let (sum, min) = (hsum_i32(sums), hsum_i32(_mm256_madd_epi16(mins, bsums(x))));
                *total += b.d * x.d * sum as f32 - b.dmin * x.d * min as f32;
            }
        }
        if N == 4 {
            store4(&mut totals, four);
        }
        totals
    }

    #[target_feature(enable = "avx2,fma")]
    fn q6_k<const N: usize>(w: &[Q6K], x: [&[Q8K]; N]) -> [f32; N] {
        let (low, top) = (_mm256_set1_epi8(0x0f), _mm256_set1_epi8(0x30));
        // block j of a half's four: scale 2j's two bytes over the low 16 bytes, 2j + 1's
        // over the high 16 (of a half's eight 16-bit scales, in both 128-bit lanes)
        let pick: [__m256i; 4] = std::array::from_fn(|j| {
            let (a, b) = (4 * j as i8, 4 * j as i8 + 2);
            let lane =
                |s: i8| _mm_set_epi8(s + 1, s, s + 1, s, s + 1, s, s + 1, s, s + 1, s, s + 1, s, s + 1, s, s + 1, s);
            _mm256_set_m128i(lane(b), lane(a))
        });
        let (mut totals, mut four) = ([0f32; N], _mm_setzero_ps());
        for (i, b) in w[..supers(w.len(), &x)].iter().enumerate() {
            // SAFETY: 16 bytes, an unaligned load
            let scales = _mm256_cvtepi8_epi16(unsafe { _mm_loadu_si128(b.scales.as_ptr().cast()) });
            let mut sums = [_mm256_setzero_si256(); N];
            for n in 0..2 {
                // scales 8n..8n + 8 in both lanes
                let half = match n {
                    0 => _mm256_permute2x128_si256::<0x00>(scales, scales),
                    _ => _mm256_permute2x128_si256::<0x11>(scales, scales),
                };
                // SAFETY: 32-byte unaligned loads inside ql (128 bytes) and qh (64)
                let (ql0, ql1, qh) = unsafe {
                    (
                        _mm256_loadu_si256(b.ql.as_ptr().add(64 * n).cast()),
                        _mm256_loadu_si256(b.ql.as_ptr().add(64 * n + 32).cast()),
                        _mm256_loadu_si256(b.qh.as_ptr().add(32 * n).cast()),
                    )
                };
                // the values unsigned, 0..64: the offset of 32 is taken off below
                let quarters = [
                    _mm256_or_si256(_mm256_and_si256(ql0, low), _mm256_and_si256(_mm256_slli_epi16(qh, 4), top)),
                    _mm256_or_si256(_mm256_and_si256(ql1, low), _mm256_and_si256(_mm256_slli_epi16(qh, 2), top)),
                    _mm256_or_si256(_mm256_and_si256(_mm256_srli_epi16(ql0, 4), low), _mm256_and_si256(qh, top)),
                    _mm256_or_si256(
                        _mm256_and_si256(_mm256_srli_epi16(ql1, 4), low),
                        _mm256_and_si256(_mm256_srli_epi16(qh, 2), top),
                    ),
                ];
                for (j, q) in quarters.into_iter().enumerate() {
                    let block = 4 * n + j;
                    // each 16-value half by its own scale
                    let block_scales = _mm256_shuffle_epi8(half, pick[j]);
                    for (sums, x) in sums.iter_mut().zip(x) {
                        add_k(sums, q, &x[i].qs[BLOCK * block..BLOCK * (block + 1)], block_scales);
                    }
                }
            }
            if N == 4 {
                // as Q4_K's: four tokens a lane
                let sums = hsum4_i32(std::array::from_fn(|t| {
                    _mm256_sub_epi32(sums[t], _mm256_slli_epi32(_mm256_madd_epi16(scales, bsums(&x[t][i])), 5))
                }));
                let scale = _mm_mul_ps(_mm_set1_ps(b.d), scales4(&x, i));
                four = _mm_add_ps(four, _mm_mul_ps(scale, _mm_cvtepi32_ps(sums)));
                continue;
            }
            for ((total, sums), x) in totals.iter_mut().zip(sums).zip(x) {
                let x = &x[i];
                let offset = _mm256_slli_epi32(_mm256_madd_epi16(scales, bsums(x)), 5);
                *total += b.d * x.d * hsum_i32(_mm256_sub_epi32(sums, offset)) as f32;
            }
        }
        if N == 4 {
            store4(&mut totals, four);
        }
        totals
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quant::{Dot, quantize};
    use candle_core::Device;
    use candle_core::quantized::{GgmlDType, QStorage, QTensor};
    use tad_base::{Rng, SplitMix64};

    /// Random bytes for `blocks` blocks of `dtype`, with finite f16 scales.
    fn random_blocks(dtype: GgmlDType, blocks: usize, seed: u64) -> Vec<u8> {
        let mut rng = SplitMix64::new(seed);
        let size = dtype.type_size();
        let mut bytes: Vec<u8> = (0..blocks * size).map(|_| rng.next_u64() as u8).collect();
        // f16 scales between about 1/1024 and 1/8, either sign: exponent bits 5..=12
        let scale = |rng: &mut SplitMix64| -> [u8; 2] {
            let bits = ((rng.below(8) as u16 + 5) << 10) | (rng.below(1024) as u16) | ((rng.below(2) as u16) << 15);
            bits.to_le_bytes()
        };
        for b in bytes.chunks_exact_mut(size) {
            let at: &[usize] = match dtype {
                GgmlDType::Q5_0 => &[0],
                GgmlDType::Q4K => &[0, 2],
                _ => &[208],
            };
            for &i in at {
                b[i..i + 2].copy_from_slice(&scale(&mut rng));
            }
        }
        bytes
    }

    /// candle's dequantization of the same bytes.
    fn candles(dtype: GgmlDType, bytes: &[u8], n: usize) -> Vec<f32> {
        let storage = QStorage::from_data(std::borrow::Cow::Borrowed(bytes), &Device::Cpu, dtype).unwrap();
        let tensor = QTensor::new(storage, n).unwrap();
        tensor.dequantize(&Device::Cpu).unwrap().to_vec1::<f32>().unwrap()
    }

    fn ours(dtype: GgmlDType, bytes: &[u8]) -> Vec<f32> {
        let mut out = Vec::new();
        match dtype {
            GgmlDType::Q5_0 => dequantize_q5_0(&read_q5_0(bytes), &mut out),
            GgmlDType::Q4K => dequantize_q4_k(&read_q4_k(bytes), &mut out),
            _ => dequantize_q6_k(&read_q6_k(bytes), &mut out),
        }
        out
    }

    #[test]
    fn nearest_even_is_round_ties_even() {
        for i in -1300..=1300 {
            for x in [i as f32 / 10.0, i as f32 / 10.0 + 0.05, i as f32 / 2.0] {
                let x = x.clamp(-128.0, 128.0);
                // equal as numbers: −0.5 gives +0 here, −0 there (the same `i8`)
                assert_eq!(nearest_even(x), x.round_ties_even(), "{x}");
            }
        }
    }

    #[test]
    fn dequantization_is_candles() {
        for (dtype, per) in [(GgmlDType::Q5_0, BLOCK), (GgmlDType::Q4K, SUPER), (GgmlDType::Q6K, SUPER)] {
            let bytes = random_blocks(dtype, 12, 5);
            let (a, b) = (ours(dtype, &bytes), candles(dtype, &bytes, 12 * per));
            assert_eq!(a.len(), b.len());
            for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                assert!((x - y).abs() <= 1e-6 * y.abs().max(1e-3), "{dtype:?} value {i}: {x} against candle's {y}");
            }
        }
    }

    #[test]
    fn dot_products_are_the_dequantized_ones() {
        let mut rng = SplitMix64::new(9);
        let x: Vec<f32> = (0..4 * SUPER).map(|_| (rng.unit() as f32 - 0.5) * 3.0).collect();
        let (mut xq, mut xk) = (Vec::new(), Vec::new());
        quantize(&x, &mut xq);
        quantize_k(&x, &mut xk);
        // the values each activation form stands for
        let xq_values: Vec<f32> = xq.iter().flat_map(|b| b.qs.iter().map(move |&q| b.d * q as f32)).collect();
        let xk_values: Vec<f32> = xk.iter().flat_map(|b| b.qs.iter().map(move |&q| b.d * q as f32)).collect();
        for dtype in [GgmlDType::Q5_0, GgmlDType::Q4K, GgmlDType::Q6K] {
            let blocks = 4 * SUPER / (dtype.block_size());
            let bytes = random_blocks(dtype, blocks, 13);
            let w = ours(dtype, &bytes);
            let crate::quant::Kernels { q5_0, q4_k, q6_k, .. } = crate::quant::Kernels::detect();
            let (got, xd) = match dtype {
                GgmlDType::Q5_0 => {
                    ([dot_q5_0(&read_q5_0(&bytes), &xq), (q5_0.one)(&read_q5_0(&bytes), &xq)], &xq_values)
                }
                GgmlDType::Q4K => {
                    ([dot_q4_k(&read_q4_k(&bytes), &xk), (q4_k.one)(&read_q4_k(&bytes), &xk)], &xk_values)
                }
                _ => ([dot_q6_k(&read_q6_k(&bytes), &xk), (q6_k.one)(&read_q6_k(&bytes), &xk)], &xk_values),
            };
            let want: f64 = w.iter().zip(xd).map(|(a, b)| f64::from(*a) * f64::from(*b)).sum();
            let size: f64 = w.iter().zip(xd).map(|(a, b)| (f64::from(*a) * f64::from(*b)).abs()).sum();
            for got in got {
                assert!((f64::from(got) - want).abs() <= 1e-5 * size, "{dtype:?}: {got} against {want}");
            }
        }
    }

    /// Q8_K as ggml makes it: the largest magnitude at −127, every value within half a step,
    /// the sums of 16 the sums of the values.
    #[test]
    fn super_block_activations_are_ggmls() {
        let mut rng = SplitMix64::new(3);
        let x: Vec<f32> = (0..2 * SUPER + 7).map(|_| (rng.unit() as f32 - 0.5) * 8.0).collect();
        let mut xk = Vec::new();
        quantize_k(&x, &mut xk);
        assert_eq!(xk.len(), 2, "a tail shorter than a super-block is left out");
        for (b, chunk) in xk.iter().zip(x.chunks_exact(SUPER)) {
            let at = (0..SUPER).max_by(|&i, &j| chunk[i].abs().total_cmp(&chunk[j].abs())).unwrap();
            assert_eq!(b.qs[at], -127);
            for (&q, &v) in b.qs.iter().zip(chunk) {
                assert!((b.d * q as f32 - v).abs() <= 0.5 * b.d.abs() * 1.0001, "{v} as {q}·{}", b.d);
            }
            for (j, &sum) in b.bsums.iter().enumerate() {
                assert_eq!(sum as i32, b.qs[16 * j..16 * j + 16].iter().map(|&q| q as i32).sum::<i32>());
            }
        }
        quantize_k(&[0.0; SUPER], &mut xk);
        assert!(xk[0].d == 0.0 && xk[0].qs.iter().all(|&q| q == 0));
        quantize_k(&[f32::NAN; SUPER], &mut xk);
        assert!(xk[0].d == 0.0, "a block without a finite extreme quantizes to zeros");
    }

    /// On the real Qwen2.5-Coder-0.5B file (when installed): every Q5_0, Q4_K and Q6_K
    /// tensor's first rows dequantize as candle's do.
    #[test]
    fn the_real_files_tensors_dequantize_as_candles() {
        let Some(path) = crate::for_tests("qwen2.5-coder-0.5b") else { return };
        let mut file = std::fs::File::open(&path).unwrap();
        let content = candle_core::quantized::gguf_file::Content::read(&mut file).unwrap();
        let mut seen: Vec<(GgmlDType, String)> = Vec::new();
        for (name, info) in &content.tensor_infos {
            let dtype = info.ggml_dtype;
            if !matches!(dtype, GgmlDType::Q5_0 | GgmlDType::Q4K | GgmlDType::Q6K) || seen.iter().any(|s| s.0 == dtype)
            {
                continue;
            }
            let tensor = content.tensor(&mut file, name, &Device::Cpu).unwrap();
            let want: Vec<f32> = tensor.dequantize(&Device::Cpu).unwrap().flatten_all().unwrap().to_vec1().unwrap();
            let bytes = tensor.data().unwrap();
            let got = ours(dtype, &bytes);
            assert_eq!(got.len(), want.len(), "{name}");
            let worst = got.iter().zip(&want).map(|(a, b)| (a - b).abs() / b.abs().max(1e-3)).fold(0f32, f32::max);
            assert!(worst <= 1e-6, "{name} ({dtype:?}): off by {worst} relative");
            seen.push((dtype, name.clone()));
        }
        assert_eq!(seen.len(), 3, "the file holds Q5_0, Q4_K and Q6_K tensors: {seen:?}");
    }

    /// This CPU's kernels, one token and four, against the scalar ones on many random rows,
    /// all formats, with activations at both ends of their range (the 16-bit pairs must not
    /// saturate).
    #[test]
    fn the_simd_kernels_are_the_scalar_ones() {
        let crate::quant::Kernels { q5_0, q4_k, q6_k, .. } = crate::quant::Kernels::detect();
        let mut rng = SplitMix64::new(21);
        for round in 0..100 {
            let supers = 1 + rng.below(4);
            let xs: Vec<Vec<f32>> = (0..4)
                .map(|t| {
                    (0..supers * SUPER)
                        .map(|i| match round % 10 {
                            0 => [127.0, -127.0][(i + t) % 2],
                            _ => (rng.unit() as f32 - 0.5) * 4.0,
                        })
                        .collect()
                })
                .collect();
            fn quantized<A>(xs: &[Vec<f32>], quantize: fn(&[f32], &mut Vec<A>)) -> Vec<Vec<A>> {
                xs.iter()
                    .map(|x| {
                        let mut q = Vec::new();
                        quantize(x, &mut q);
                        q
                    })
                    .collect()
            }
            let (xq, xk) = (quantized(&xs, quantize), quantized(&xs, quantize_k));
            // `exact`: the same bits (the K formats), else the same up to float rounding
            fn agree<B, A>(k: &FormatKernels<B, A>, scalar: Dot<B, A>, w: &[B], x: &[Vec<A>], exact: bool, what: &str) {
                let x4 = [&x[0][..], &x[1][..], &x[2][..], &x[3][..]];
                let four = (k.four)(w, x4);
                for (t, x) in x4.into_iter().enumerate() {
                    let want = scalar(w, x);
                    for got in [(k.one)(w, x), four[t]] {
                        match exact {
                            true => assert_eq!(got.to_bits(), want.to_bits(), "{what}: {got} against {want}"),
                            false => assert!(
                                (got - want).abs() <= 1e-4 * want.abs().max(1.0),
                                "{what}: {got} against {want}"
                            ),
                        }
                    }
                }
            }
            let (q5, q4, q6) = (GgmlDType::Q5_0, GgmlDType::Q4K, GgmlDType::Q6K);
            agree(&q5_0, dot_q5_0, &read_q5_0(&random_blocks(q5, supers * 8, round)), &xq, false, "Q5_0");
            agree(&q4_k, dot_q4_k, &read_q4_k(&random_blocks(q4, supers, round)), &xk, true, "Q4_K");
            agree(&q6_k, dot_q6_k, &read_q6_k(&random_blocks(q6, supers, round)), &xk, true, "Q6_K");
        }
    }
}
