//! The quantized formats of Qwen2.5-Coder's Q4_K_M files beside [`crate::quant`]'s: Q5_0
//! (32 values a block, 5 bits) and ggml's super-blocks of 256 values, Q4_K (eight
//! sub-blocks of 32, each with a 6-bit scale and minimum) and Q6_K (sixteen sub-blocks of 16,
//! each with an 8-bit scale).
//!
//! Their dot products take the same activations as the other kernels: blocks of 32 values
//! quantized to 8 bits with their sum ([`Q8_1`]), eight to a super-block. Each block's
//! integer sum is scaled once, so a product is the dequantized weights against the
//! dequantized activations, up to float rounding. A super-block is unpacked to its 256
//! small integers first, which keeps the arithmetic the same for every format.
//!
//! The layouts are ggml's (`ggml-common.h`, `block_q5_0`, `block_q4_K`, `block_q6_K`); the
//! tests hold the dequantization to candle's on random blocks and on the real files.

use crate::quant::{BLOCK, Q8_1, f16_to_f32};

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
    /// Eight 6-bit scales and eight 6-bit minima, packed (`scale_min`).
    pub scales: [u8; 12],
    /// Per 64 values: the first 32 in the low nibbles of 32 bytes, the next 32 in their
    /// high nibbles.
    pub qs: [u8; 128],
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
        .map(|b| Q4K {
            d: half(b, 0),
            dmin: half(b, 2),
            scales: b[4..16].try_into().unwrap_or([0; 12]),
            qs: b[16..144].try_into().unwrap_or([0; 128]),
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

impl Q4K {
    /// Sub-block `j`'s 6-bit scale and minimum (ggml's `get_scale_min_k4`).
    fn scale_min(&self, j: usize) -> (u8, u8) {
        let q = &self.scales;
        if j < 4 {
            (q[j] & 63, q[j + 4] & 63)
        } else {
            ((q[j + 4] & 0x0f) | ((q[j - 4] >> 6) << 4), (q[j + 4] >> 4) | ((q[j] >> 6) << 4))
        }
    }

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
            let (sc, m) = b.scale_min(sub);
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

/// A weight row unpacked for dot products: its values as small integers, and for each
/// block of 32 the factors `(f1, f2, f3)` of `dx·(f1·Σ₁ + f2·Σ₂) − f3·s`, where Σ₁ and Σ₂
/// are the integer sums of its two 16-value halves against an activation block (`dx`,
/// `s = dx·Σx`). One form for every format, so a row is unpacked once for all the tokens
/// of a chunk, and the scalar and AVX2 kernels differ only in the integer sums (exact).
#[derive(Clone, Debug, Default)]
pub struct Unpacked {
    pub q: Vec<i8>,
    pub factors: Vec<[f32; 3]>,
}

impl Unpacked {
    pub fn q5_0(blocks: &[Q5_0], out: &mut Unpacked) {
        out.clear();
        for b in blocks {
            out.q.extend(b.values());
            out.factors.push([b.d, b.d, 0.0]);
        }
    }

    pub fn q4_k(blocks: &[Q4K], out: &mut Unpacked) {
        out.clear();
        for b in blocks {
            out.q.extend(b.values().map(|v| v as i8));
            for sub in 0..SUPER / BLOCK {
                let (sc, m) = b.scale_min(sub);
                let scale = b.d * sc as f32;
                out.factors.push([scale, scale, b.dmin * m as f32]);
            }
        }
    }

    pub fn q6_k(blocks: &[Q6K], out: &mut Unpacked) {
        out.clear();
        for b in blocks {
            out.q.extend(b.values());
            for sub in 0..SUPER / BLOCK {
                out.factors.push([b.d * b.scales[2 * sub] as f32, b.d * b.scales[2 * sub + 1] as f32, 0.0]);
            }
        }
    }

    fn clear(&mut self) {
        self.q.clear();
        self.factors.clear();
    }

    /// The row against activations `x` (as many blocks), the halves' sums from `halves`.
    pub fn dot(&self, x: &[Q8_1], halves: Halves) -> f32 {
        let mut total = 0f32;
        for ((q, [f1, f2, f3]), x) in self.q.chunks_exact(BLOCK).zip(&self.factors).zip(x) {
            let q: &[i8; BLOCK] = q.try_into().unwrap_or(&[0; BLOCK]);
            let (s1, s2) = halves(q, &x.qs);
            total += x.d * (f1 * s1 as f32 + f2 * s2 as f32) - f3 * x.s;
        }
        total
    }
}

/// The integer dot products of the two 16-value halves of two blocks of 32.
pub type Halves = fn(&[i8; BLOCK], &[i8; BLOCK]) -> (i32, i32);

pub fn halves_scalar(a: &[i8; BLOCK], b: &[i8; BLOCK]) -> (i32, i32) {
    let sum = |a: &[i8], b: &[i8]| a.iter().zip(b).map(|(&x, &y)| x as i32 * y as i32).sum::<i32>();
    (sum(&a[..16], &b[..16]), sum(&a[16..], &b[16..]))
}

/// [`halves_scalar`] with AVX2, when the CPU has it (the same integers).
pub fn halves() -> Halves {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        return avx2::halves_safe;
    }
    halves_scalar
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::BLOCK;
    use std::arch::x86_64::*;

    pub fn halves_safe(a: &[i8; BLOCK], b: &[i8; BLOCK]) -> (i32, i32) {
        // SAFETY: chosen only when the CPU has AVX2 (`super::halves`)
        unsafe { halves(a, b) }
    }

    /// `a`'s values are small (|a| ≤ 32 in every format here), so the pairwise 16-bit
    /// sums of `|a|·(±b)` cannot saturate.
    #[target_feature(enable = "avx2")]
    fn halves(a: &[i8; BLOCK], b: &[i8; BLOCK]) -> (i32, i32) {
        // SAFETY: both arrays are 32 bytes; unaligned loads
        let (va, vb) = unsafe {
            (_mm256_loadu_si256(a.as_ptr().cast::<__m256i>()), _mm256_loadu_si256(b.as_ptr().cast::<__m256i>()))
        };
        let products = _mm256_maddubs_epi16(_mm256_sign_epi8(va, va), _mm256_sign_epi8(vb, va));
        let sums = _mm256_madd_epi16(products, _mm256_set1_epi16(1));
        let half = |v: __m128i| {
            let v = _mm_add_epi32(v, _mm_shuffle_epi32(v, 0b01_00_11_10));
            let v = _mm_add_epi32(v, _mm_shuffle_epi32(v, 0b10_11_00_01));
            _mm_cvtsi128_si32(v)
        };
        (half(_mm256_castsi256_si128(sums)), half(_mm256_extracti128_si256(sums, 1)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quant::quantize;
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

    /// A row of blocks unpacked by `unpack`.
    fn unpacked<B>(unpack: fn(&[B], &mut Unpacked), blocks: &[B]) -> Unpacked {
        let mut row = Unpacked::default();
        unpack(blocks, &mut row);
        row
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
        let mut xq = Vec::new();
        quantize(&x, &mut xq);
        let xd: Vec<f32> = xq.iter().flat_map(|b| b.qs.iter().map(move |&q| b.d * q as f32)).collect();
        for dtype in [GgmlDType::Q5_0, GgmlDType::Q4K, GgmlDType::Q6K] {
            let blocks = 4 * SUPER / (dtype.block_size());
            let bytes = random_blocks(dtype, blocks, 13);
            let w = ours(dtype, &bytes);
            let want: f64 = w.iter().zip(&xd).map(|(a, b)| f64::from(*a) * f64::from(*b)).sum();
            let got = match dtype {
                GgmlDType::Q5_0 => unpacked(Unpacked::q5_0, &read_q5_0(&bytes)),
                GgmlDType::Q4K => unpacked(Unpacked::q4_k, &read_q4_k(&bytes)),
                _ => unpacked(Unpacked::q6_k, &read_q6_k(&bytes)),
            }
            .dot(&xq, halves_scalar);
            let size: f64 = w.iter().zip(&xd).map(|(a, b)| (f64::from(*a) * f64::from(*b)).abs()).sum();
            assert!((f64::from(got) - want).abs() <= 1e-5 * size, "{dtype:?}: {got} against {want}");
        }
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

    #[test]
    fn the_simd_halves_are_the_scalar_ones() {
        let mut rng = SplitMix64::new(21);
        for _ in 0..1000 {
            let mut a = [0i8; BLOCK];
            let mut b = [0i8; BLOCK];
            a.iter_mut().for_each(|v| *v = rng.below(65) as i8 - 32);
            b.iter_mut().for_each(|v| *v = (rng.below(255) as i32 - 127) as i8);
            assert_eq!(halves()(&a, &b), halves_scalar(&a, &b), "{a:?} · {b:?}");
        }
    }
}
