//! Quantized blocks and their dot products, in ggml's formats (32 values a block):
//! weights in Q4_1 (`d·q + m`, q in 0..16) or Q8_0 (`d·q`, q in −127..=127), activations
//! quantized on the fly to 8 bits a block with their sum (what llama.cpp calls Q8_1).
//!
//! A dot product of a weight row and an activation vector is then integer products summed
//! a block at a time, scaled once per block. On x86-64 with AVX2 and FMA (detected at run
//! time) the blocks go through 256-bit integer multiply-adds; elsewhere through the same
//! arithmetic in scalar code, so both give the same sums up to float rounding. Attention
//! over the KV cache (scores, softmax, the weighted sum of values) is chosen the same way.

/// Values in a block.
pub const BLOCK: usize = 32;

#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Q4_1 {
    pub d: f32,
    pub m: f32,
    /// Value `j` in the low nibble of byte `j`, value `j + 16` in its high nibble.
    pub qs: [u8; 16],
}

#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Q8_0 {
    pub d: f32,
    pub qs: [i8; 32],
}

/// An activation block: `d·q`, and `s = d·Σq` for Q4_1's offset term.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Q8_1 {
    pub d: f32,
    pub s: f32,
    pub qs: [i8; 32],
}

impl Default for Q8_1 {
    fn default() -> Self {
        Q8_1 { d: 0.0, s: 0.0, qs: [0; 32] }
    }
}

/// IEEE half to single precision (the scales in a GGUF file).
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1f) as u32;
    let frac = (h & 0x3ff) as u32;
    let bits = match (exp, frac) {
        (0, 0) => sign,
        (0, _) => {
            // subnormal: renormalise
            let mut e = 127 - 15 + 1;
            let mut f = frac;
            while f & 0x400 == 0 {
                f <<= 1;
                e -= 1;
            }
            sign | (e << 23) | ((f & 0x3ff) << 13)
        }
        (0x1f, _) => sign | 0x7f80_0000 | (frac << 13),
        _ => sign | ((exp + 127 - 15) << 23) | (frac << 13),
    };
    f32::from_bits(bits)
}

/// Single to half precision, rounded to nearest even (the KV cache's keys and values);
/// beyond half's range, infinity; NaN stays NaN.
pub fn f32_to_f16(x: f32) -> u16 {
    let bits = x.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exp = ((bits >> 23) & 0xff) as i32;
    let mant = bits & 0x7f_ffff;
    if exp == 0xff {
        return sign | 0x7c00 | if mant != 0 { 0x200 } else { 0 };
    }
    let e = exp - 127 + 15;
    if e >= 0x1f {
        return sign | 0x7c00;
    }
    if e <= 0 {
        // a subnormal half (or zero): the mantissa with its implicit bit, shifted
        if e < -10 {
            return sign;
        }
        let m = mant | 0x80_0000;
        let shift = (14 - e) as u32;
        let rounded = (m + (1 << (shift - 1)) - 1 + ((m >> shift) & 1)) >> shift;
        return sign | rounded as u16;
    }
    let (m, rest) = (mant >> 13, mant & 0x1fff);
    let mut h = ((e as u32) << 10) | m;
    // a carry out of the mantissa raises the exponent, as it should
    if rest > 0x1000 || (rest == 0x1000 && m & 1 == 1) {
        h += 1;
    }
    sign | h as u16
}

/// Q4_1 blocks from a GGUF tensor's bytes (20 bytes a block: d, m as f16, 16 bytes).
pub fn read_q4_1(bytes: &[u8]) -> Vec<Q4_1> {
    bytes
        .chunks_exact(20)
        .map(|b| Q4_1 {
            d: f16_to_f32(u16::from_le_bytes([b[0], b[1]])),
            m: f16_to_f32(u16::from_le_bytes([b[2], b[3]])),
            qs: b[4..20].try_into().unwrap_or([0; 16]),
        })
        .collect()
}

/// Q8_0 blocks from a GGUF tensor's bytes (34 bytes a block: d as f16, 32 bytes).
pub fn read_q8_0(bytes: &[u8]) -> Vec<Q8_0> {
    bytes
        .chunks_exact(34)
        .map(|b| {
            let mut qs = [0i8; 32];
            for (q, &byte) in qs.iter_mut().zip(&b[2..34]) {
                *q = byte as i8;
            }
            Q8_0 { d: f16_to_f32(u16::from_le_bytes([b[0], b[1]])), qs }
        })
        .collect()
}

/// Quantizes `x` (a multiple of 32 long) into `out`, a block per 32 values.
pub fn quantize(x: &[f32], out: &mut Vec<Q8_1>) {
    out.clear();
    for chunk in x.chunks_exact(BLOCK) {
        let amax = chunk.iter().fold(0f32, |a, v| a.max(v.abs()));
        let d = amax / 127.0;
        let inv = if d > 0.0 { 1.0 / d } else { 0.0 };
        let mut block = Q8_1 { d, ..Q8_1::default() };
        let mut sum = 0i32;
        for (q, v) in block.qs.iter_mut().zip(chunk) {
            *q = (v * inv).round() as i8;
            sum += *q as i32;
        }
        block.s = d * sum as f32;
        out.push(block);
    }
}

/// A row's product with one token's activations `A`, and with four at once (the row's
/// blocks unpacked once for the four).
pub type Dot<B, A = Q8_1> = fn(&[B], &[A]) -> f32;
pub type Dot4<B, A = Q8_1> = fn(&[B], [&[A]; 4]) -> [f32; 4];

/// The kernels of one format.
pub struct FormatKernels<B, A = Q8_1> {
    pub one: Dot<B, A>,
    pub four: Dot4<B, A>,
}

// by hand: a derive would ask `B: Copy` of the blocks
impl<B, A> Clone for FormatKernels<B, A> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<B, A> Copy for FormatKernels<B, A> {}

/// The dot products, chosen once for this CPU.
#[derive(Clone, Copy)]
pub struct Kernels {
    pub q4_1: FormatKernels<Q4_1>,
    pub q8_0: Dot<Q8_0>,
    pub q5_0: FormatKernels<crate::kquant::Q5_0>,
    pub q4_k: FormatKernels<crate::kquant::Q4K, crate::kquant::Q8K>,
    pub q6_k: FormatKernels<crate::kquant::Q6K, crate::kquant::Q8K>,
    /// `out = softmax(q·kᵀ·scale)·v` over a key/value head's positions for each query head
    /// that shares it (`q` and `out` hold them one after another, `Heads::dim` wide each;
    /// `scores` is scratch), the cache in half precision.
    pub attend: Attend,
    pub name: &'static str,
}

/// Attention over one key/value head for the query heads that share it ([`Kernels::attend`]).
pub type Attend = fn(&[f32], &Heads, f32, &mut Vec<f32>, &mut [f32]);

/// One key/value head of the KV cache: position `p`'s vector at `p·stride + offset`, `dim`
/// wide, in half precision (as llama.cpp keeps it: half the memory and the bandwidth of f32).
pub struct Heads<'a> {
    pub keys: &'a [u16],
    pub values: &'a [u16],
    pub stride: usize,
    pub offset: usize,
    pub dim: usize,
    pub positions: usize,
}

/// Each query head of `q` against `heads` alone, through `attend_with`.
#[inline(always)]
fn attend_each(
    dot: impl Fn(&[f32], &[u16]) -> f32 + Copy,
    axpy: impl Fn(&mut [f32], f32, &[u16]) + Copy,
    q: &[f32],
    heads: &Heads,
    scale: f32,
    scores: &mut Vec<f32>,
    out: &mut [f32],
) {
    for (q, out) in q.chunks_exact(heads.dim.max(1)).zip(out.chunks_exact_mut(heads.dim.max(1))) {
        attend_with(dot, axpy, q, heads, scale, scores, out);
    }
}

/// Attention written over any dot product and `axpy`.
#[inline(always)]
fn attend_with(
    dot: impl Fn(&[f32], &[u16]) -> f32,
    axpy: impl Fn(&mut [f32], f32, &[u16]),
    q: &[f32],
    heads: &Heads,
    scale: f32,
    scores: &mut Vec<f32>,
    out: &mut [f32],
) {
    let d = q.len();
    scores.clear();
    scores.extend((0..heads.positions).map(|p| {
        let at = p * heads.stride + heads.offset;
        dot(q, &heads.keys[at..at + d]) * scale
    }));
    let max = scores.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
    let mut sum = 0.0;
    for v in scores.iter_mut() {
        *v = (*v - max).exp();
        sum += *v;
    }
    out.fill(0.0);
    for (p, &w) in scores.iter().enumerate() {
        let at = p * heads.stride + heads.offset;
        axpy(out, w / sum, &heads.values[at..at + d]);
    }
}

impl Kernels {
    pub fn detect() -> Kernels {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("f16c")
        {
            let (q5_0, q4_k, q6_k) = crate::kquant::avx2_kernels();
            return Kernels {
                q4_1: FormatKernels { one: avx2::q4_1_safe, four: avx2::q4_1_x4_safe },
                q8_0: avx2::q8_0_safe,
                q5_0,
                q4_k,
                q6_k,
                attend: avx2::attend_safe,
                name: "avx2",
            };
        }
        Kernels::scalar()
    }

    pub fn scalar() -> Kernels {
        let (q5_0, q4_k, q6_k) = crate::kquant::scalar_kernels();
        Kernels {
            q4_1: FormatKernels { one: dot_q4_1_scalar, four: |w, x| x.map(|x| dot_q4_1_scalar(w, x)) },
            q8_0: dot_q8_0_scalar,
            q5_0,
            q4_k,
            q6_k,
            attend: |q, h, scale, scores, out| attend_each(dot_scalar, axpy_scalar, q, h, scale, scores, out),
            name: "scalar",
        }
    }
}

fn dot_scalar(a: &[f32], b: &[u16]) -> f32 {
    // eight lanes, so the compiler keeps them in vector registers
    let mut lanes = [0f32; 8];
    let (ac, bc) = (a.chunks_exact(8), b.chunks_exact(8));
    let rest: f32 = ac.remainder().iter().zip(bc.remainder()).map(|(x, &y)| x * f16_to_f32(y)).sum();
    for (x, y) in ac.zip(bc) {
        for i in 0..8 {
            lanes[i] += x[i] * f16_to_f32(y[i]);
        }
    }
    lanes.iter().sum::<f32>() + rest
}

fn axpy_scalar(out: &mut [f32], w: f32, v: &[u16]) {
    for (o, &x) in out.iter_mut().zip(v) {
        *o += w * f16_to_f32(x);
    }
}

pub fn dot_q4_1_scalar(w: &[Q4_1], x: &[Q8_1]) -> f32 {
    let mut total = 0f32;
    for (w, x) in w.iter().zip(x) {
        let mut sum = 0i32;
        for j in 0..16 {
            let byte = w.qs[j];
            sum += (byte & 0x0f) as i32 * x.qs[j] as i32 + (byte >> 4) as i32 * x.qs[j + 16] as i32;
        }
        total += w.d * x.d * sum as f32 + w.m * x.s;
    }
    total
}

pub fn dot_q8_0_scalar(w: &[Q8_0], x: &[Q8_1]) -> f32 {
    let mut total = 0f32;
    for (w, x) in w.iter().zip(x) {
        let sum: i32 = w.qs.iter().zip(&x.qs).map(|(&a, &b)| a as i32 * b as i32).sum();
        total += w.d * x.d * sum as f32;
    }
    total
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Heads, Q4_1, Q8_0, Q8_1};
    use std::arch::x86_64::*;

    pub fn q4_1_safe(w: &[Q4_1], x: &[Q8_1]) -> f32 {
        // SAFETY: chosen only when the CPU has AVX2 and FMA (Kernels::detect)
        unsafe { q4_1(w, x) }
    }

    pub fn q8_0_safe(w: &[Q8_0], x: &[Q8_1]) -> f32 {
        // SAFETY: as above
        unsafe { q8_0(w, x) }
    }

    pub fn q4_1_x4_safe(w: &[Q4_1], x: [&[Q8_1]; 4]) -> [f32; 4] {
        // SAFETY: as above
        unsafe { q4_1_x4(w, x) }
    }

    pub fn attend_safe(q: &[f32], heads: &Heads, scale: f32, scores: &mut Vec<f32>, out: &mut [f32]) {
        // SAFETY: as above (and F16C, also checked there)
        unsafe { attend(q, heads, scale, scores, out) }
    }

    /// Eight halves from `at`, widened (F16C).
    #[target_feature(enable = "avx2,fma,f16c")]
    #[inline]
    unsafe fn halves(at: *const u16) -> __m256 {
        // SAFETY: the caller keeps `at + 8` within its slice
        unsafe { _mm256_cvtph_ps(_mm_loadu_si128(at.cast())) }
    }

    /// The query heads of a group at once: each key and value is widened once for all of
    /// them, each head's products summed in a register of its own (a dot product is no
    /// chain of dependent multiply-adds). Heads of a width that is no multiple of 16, and
    /// groups of more than 8, take the plain loop.
    #[target_feature(enable = "avx2,fma,f16c")]
    fn attend(q: &[f32], heads: &Heads, scale: f32, scores: &mut Vec<f32>, out: &mut [f32]) {
        let d = heads.dim;
        let group = q.len().checked_div(d).unwrap_or(0);
        let end = heads.positions.saturating_sub(1) * heads.stride + heads.offset + d;
        let fits = d.is_multiple_of(16)
            && group * d == q.len()
            && out.len() == q.len()
            && heads.positions > 0
            && end <= heads.keys.len()
            && end <= heads.values.len();
        let grouped: Option<super::Attend> = match group {
            _ if !fits => None,
            1 => Some(grouped::<1>),
            2 => Some(grouped::<2>),
            3 => Some(grouped::<3>),
            4 => Some(grouped::<4>),
            5 => Some(grouped::<5>),
            6 => Some(grouped::<6>),
            7 => Some(grouped::<7>),
            8 => Some(grouped::<8>),
            _ => None,
        };
        match grouped {
            Some(f) => f(q, heads, scale, scores, out),
            None => super::attend_each(|a, b| dot(a, b), |o, w, v| axpy(o, w, v), q, heads, scale, scores, out),
        }
    }

    /// [`attend`] for `G` query heads; the caller has checked every bound.
    #[target_feature(enable = "avx2,fma,f16c")]
    fn grouped<const G: usize>(q: &[f32], heads: &Heads, scale: f32, scores: &mut Vec<f32>, out: &mut [f32]) {
        let (d, n) = (heads.dim, heads.positions);
        scores.clear();
        scores.resize(G * n, 0.0);
        let at = |p: usize| p * heads.stride + heads.offset;
        // SAFETY: every key and value read is within `at(n - 1) + d`, which `attend` checked
        // against both slices; q and out are G·d long, so are the scores G·n
        unsafe {
            for p in 0..n {
                let key = heads.keys.as_ptr().add(at(p));
                let mut acc = [_mm256_setzero_ps(); G];
                for j in (0..d).step_by(8) {
                    let k = halves(key.add(j));
                    for (h, acc) in acc.iter_mut().enumerate() {
                        *acc = _mm256_fmadd_ps(_mm256_loadu_ps(q.as_ptr().add(h * d + j)), k, *acc);
                    }
                }
                for (h, acc) in acc.into_iter().enumerate() {
                    *scores.get_unchecked_mut(h * n + p) = hsum(acc) * scale;
                }
            }
            let mut sums = [0f32; G];
            for (sum, head) in sums.iter_mut().zip(scores.chunks_exact_mut(n)) {
                let max = head.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
                for v in head.iter_mut() {
                    *v = (*v - max).exp();
                    *sum += *v;
                }
            }
            // 16 of the d values at a time, for every head of the group
            for j in (0..d).step_by(16) {
                let mut o = [[_mm256_setzero_ps(); 2]; G];
                for p in 0..n {
                    let value = heads.values.as_ptr().add(at(p) + j);
                    let (v0, v1) = (halves(value), halves(value.add(8)));
                    for (h, o) in o.iter_mut().enumerate() {
                        let w = _mm256_set1_ps(*scores.get_unchecked(h * n + p));
                        o[0] = _mm256_fmadd_ps(w, v0, o[0]);
                        o[1] = _mm256_fmadd_ps(w, v1, o[1]);
                    }
                }
                for (h, o) in o.iter().enumerate() {
                    let inv = _mm256_set1_ps(1.0 / sums[h]);
                    let dst = out.as_mut_ptr().add(h * d + j);
                    _mm256_storeu_ps(dst, _mm256_mul_ps(o[0], inv));
                    _mm256_storeu_ps(dst.add(8), _mm256_mul_ps(o[1], inv));
                }
            }
        }
    }

    #[target_feature(enable = "avx2,fma,f16c")]
    fn dot(a: &[f32], b: &[u16]) -> f32 {
        let n = a.len().min(b.len());
        let mut acc = _mm256_setzero_ps();
        let mut i = 0;
        while i + 8 <= n {
            // SAFETY: i + 8 <= both lengths
            let (x, y) = unsafe { (_mm256_loadu_ps(a.as_ptr().add(i)), halves(b.as_ptr().add(i))) };
            acc = _mm256_fmadd_ps(x, y, acc);
            i += 8;
        }
        let mut total = hsum(acc);
        while i < n {
            total += a[i] * super::f16_to_f32(b[i]);
            i += 1;
        }
        total
    }

    #[target_feature(enable = "avx2,fma,f16c")]
    fn axpy(out: &mut [f32], w: f32, v: &[u16]) {
        let n = out.len().min(v.len());
        let weight = _mm256_set1_ps(w);
        let mut i = 0;
        while i + 8 <= n {
            // SAFETY: i + 8 <= both lengths
            unsafe {
                let o = out.as_mut_ptr().add(i);
                _mm256_storeu_ps(o, _mm256_fmadd_ps(weight, halves(v.as_ptr().add(i)), _mm256_loadu_ps(o)));
            }
            i += 8;
        }
        while i < n {
            out[i] += w * super::f16_to_f32(v[i]);
            i += 1;
        }
    }

    #[target_feature(enable = "avx2,fma")]
    fn q4_1_x4(w: &[Q4_1], x: [&[Q8_1]; 4]) -> [f32; 4] {
        let mut acc = [_mm256_setzero_ps(); 4];
        let mut offsets = [0f32; 4];
        let low = _mm256_set1_epi8(0x0f);
        let ones = _mm256_set1_epi16(1);
        let n = x.iter().map(|x| x.len()).min().unwrap_or(0).min(w.len());
        for (b, w) in w[..n].iter().enumerate() {
            // SAFETY: 16 bytes; unaligned load
            let packed = unsafe { _mm_loadu_si128(w.qs.as_ptr() as *const __m128i) };
            let nibbles = _mm256_and_si256(_mm256_set_m128i(_mm_srli_epi16(packed, 4), packed), low);
            for t in 0..4 {
                let y = &x[t][b];
                offsets[t] += w.m * y.s;
                // SAFETY: 32 bytes; unaligned load
                let q = unsafe { _mm256_loadu_si256(y.qs.as_ptr() as *const __m256i) };
                let sums = _mm256_cvtepi32_ps(_mm256_madd_epi16(_mm256_maddubs_epi16(nibbles, q), ones));
                acc[t] = _mm256_fmadd_ps(_mm256_set1_ps(w.d * y.d), sums, acc[t]);
            }
        }
        [0, 1, 2, 3].map(|t| hsum(acc[t]) + offsets[t])
    }

    #[target_feature(enable = "avx2,fma")]
    fn hsum(v: __m256) -> f32 {
        let low = _mm256_castps256_ps128(v);
        let high = _mm256_extractf128_ps(v, 1);
        let s = _mm_add_ps(low, high);
        let s = _mm_add_ps(s, _mm_movehl_ps(s, s));
        let s = _mm_add_ss(s, _mm_movehdup_ps(s));
        _mm_cvtss_f32(s)
    }

    #[target_feature(enable = "avx2,fma")]
    fn q4_1(w: &[Q4_1], x: &[Q8_1]) -> f32 {
        let mut acc = _mm256_setzero_ps();
        let mut offsets = 0f32;
        let low = _mm256_set1_epi8(0x0f);
        let ones = _mm256_set1_epi16(1);
        for (w, x) in w.iter().zip(x) {
            offsets += w.m * x.s;
            // SAFETY: qs are 16 and 32 bytes long; unaligned loads
            let packed = unsafe { _mm_loadu_si128(w.qs.as_ptr() as *const __m128i) };
            let nibbles = _mm256_and_si256(_mm256_set_m128i(_mm_srli_epi16(packed, 4), packed), low);
            let y = unsafe { _mm256_loadu_si256(x.qs.as_ptr() as *const __m256i) };
            let pairs = _mm256_maddubs_epi16(nibbles, y);
            let sums = _mm256_cvtepi32_ps(_mm256_madd_epi16(pairs, ones));
            acc = _mm256_fmadd_ps(_mm256_set1_ps(w.d * x.d), sums, acc);
        }
        hsum(acc) + offsets
    }

    #[target_feature(enable = "avx2,fma")]
    fn q8_0(w: &[Q8_0], x: &[Q8_1]) -> f32 {
        let mut acc = _mm256_setzero_ps();
        let ones = _mm256_set1_epi16(1);
        for (w, x) in w.iter().zip(x) {
            // SAFETY: 32-byte arrays; unaligned loads
            let a = unsafe { _mm256_loadu_si256(w.qs.as_ptr() as *const __m256i) };
            let b = unsafe { _mm256_loadu_si256(x.qs.as_ptr() as *const __m256i) };
            // |a| · (b with a's sign): unsigned × signed, as maddubs takes them
            let pairs = _mm256_maddubs_epi16(_mm256_sign_epi8(a, a), _mm256_sign_epi8(b, a));
            let sums = _mm256_cvtepi32_ps(_mm256_madd_epi16(pairs, ones));
            acc = _mm256_fmadd_ps(_mm256_set1_ps(w.d * x.d), sums, acc);
        }
        hsum(acc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seeded(n: usize, seed: u64) -> Vec<f32> {
        let mut state = seed;
        (0..n)
            .map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((state >> 33) as f32 / (1u64 << 31) as f32) * 2.0 - 1.0
            })
            .collect()
    }

    /// Every half survives the way there and back, and single precision rounds to the
    /// nearest half (ties to even) as IEEE's conversion does.
    #[test]
    fn halves_round_trip_and_round_to_nearest_even() {
        for h in 0..=u16::MAX {
            let x = f16_to_f32(h);
            if x.is_nan() {
                assert!(f16_to_f32(f32_to_f16(x)).is_nan());
            } else {
                assert_eq!(f32_to_f16(x), h, "{h:#06x} ({x})");
            }
        }
        assert_eq!(f32_to_f16(1.0 + 2f32.powi(-11)), 0x3c00, "a tie goes to the even 1.0");
        assert_eq!(f32_to_f16(1.0 + 3.0 * 2f32.powi(-11)), 0x3c02, "a tie goes to the even 1 + 2^-9");
        assert_eq!(f32_to_f16(65520.0), 0x7c00, "past the largest half: infinity");
        assert_eq!(f32_to_f16(2f32.powi(-25)), 0, "half the smallest subnormal: a tie to zero");
        assert_eq!(f32_to_f16(3.0 * 2f32.powi(-26)), 1, "more than half of it: the smallest subnormal");
        assert_eq!(f32_to_f16(-0.0), 0x8000);
    }

    #[test]
    fn half_precision_converts_exactly() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    #[test]
    fn kernels_agree_with_the_float_dot_product() {
        let x = seeded(256, 1);
        let mut xq = Vec::new();
        quantize(&x, &mut xq);
        // Q4_1 weights with known values
        let w: Vec<Q4_1> = (0..8)
            .map(|b| {
                let mut qs = [0u8; 16];
                for (j, q) in qs.iter_mut().enumerate() {
                    *q = ((j + b) % 16) as u8 | ((((j * 7 + b) % 16) as u8) << 4);
                }
                Q4_1 { d: 0.01 * (b as f32 + 1.0), m: -0.05, qs }
            })
            .collect();
        let exact: f32 = (0..256)
            .map(|i| {
                let (b, j) = (i / 32, i % 32);
                let q = if j < 16 { w[b].qs[j] & 15 } else { w[b].qs[j - 16] >> 4 };
                (w[b].d * q as f32 + w[b].m) * x[i]
            })
            .sum();
        for k in [Kernels::scalar(), Kernels::detect()] {
            let got = (k.q4_1.one)(&w, &xq);
            assert!((got - exact).abs() < 0.02 * exact.abs().max(1.0), "{}: {got} vs {exact}", k.name);
        }
        let w8: Vec<Q8_0> = (0..8)
            .map(|b| {
                let mut qs = [0i8; 32];
                for (j, q) in qs.iter_mut().enumerate() {
                    *q = ((j as i32 * 13 + b * 31) % 255 - 127) as i8;
                }
                Q8_0 { d: 0.003, qs }
            })
            .collect();
        let exact8: f32 = (0..256).map(|i| w8[i / 32].d * w8[i / 32].qs[i % 32] as f32 * x[i]).sum();
        let four = [xq.as_slice(); 4];
        for k in [Kernels::scalar(), Kernels::detect()] {
            let single = (k.q4_1.one)(&w, &xq);
            assert!((k.q4_1.four)(&w, four).iter().all(|v| (v - single).abs() <= 1e-4 * single.abs().max(1.0)));
            // attention over the second head of a 2-head cache: heads 12, 64 and 128 wide,
            // groups of 1, 3, 6 and 9 query heads (9: past the widest group the kernels take),
            // over 5 positions and over 37
            for (d, group, positions) in [(12, 1, 5), (64, 1, 5), (64, 3, 37), (128, 6, 5), (128, 6, 37), (64, 9, 5)] {
                let halves = |v: Vec<f32>| -> (Vec<u16>, Vec<f32>) {
                    let h: Vec<u16> = v.iter().map(|&x| f32_to_f16(x)).collect();
                    let back = h.iter().map(|&x| f16_to_f32(x)).collect();
                    (h, back)
                };
                let q = seeded(group * d, 2);
                let cache = |seed| halves(seeded(2 * positions * d, seed));
                let ((keys16, keys), (values16, values)) = (cache(3), cache(4));
                let heads = Heads { keys: &keys16, values: &values16, stride: 2 * d, offset: d, dim: d, positions };
                let mut out = vec![0.0; group * d];
                (k.attend)(&q, &heads, 0.5, &mut Vec::new(), &mut out);
                for (h, (q, out)) in q.chunks_exact(d).zip(out.chunks_exact(d)).enumerate() {
                    let at = |p: usize| p * 2 * d + d;
                    let scores: Vec<f32> =
                        (0..positions).map(|p| (0..d).map(|i| q[i] * keys[at(p) + i]).sum::<f32>() * 0.5).collect();
                    let max = scores.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
                    let total: f32 = scores.iter().map(|s| (s - max).exp()).sum();
                    for (i, o) in out.iter().enumerate() {
                        let exact: f32 =
                            (0..positions).map(|p| (scores[p] - max).exp() / total * values[at(p) + i]).sum();
                        assert!((o - exact).abs() < 1e-5, "{} d={d} head {h} of {group}: {o} vs {exact}", k.name);
                    }
                }
            }
        }
        let scalar = (Kernels::scalar().q8_0)(&w8, &xq);
        let fast = (Kernels::detect().q8_0)(&w8, &xq);
        assert!((scalar - exact8).abs() < 0.02 * exact8.abs().max(1.0), "{scalar} vs {exact8}");
        assert!((fast - scalar).abs() <= 1e-4 * scalar.abs().max(1.0), "{fast} vs {scalar}");
    }
}
