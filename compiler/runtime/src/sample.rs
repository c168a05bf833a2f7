//! Parameters per run: each slot drawn uniformly from its range by a seeded generator
//! (SplitMix64), so a seed always gives the same values.

use tad_bytecode::ParamSlot;

/// SplitMix64 (Steele, Lea and Flood 2014).
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x5DEE_CE66_D1CE_4E5B)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The slots' values for a seed; `None` gives every slot its default.
pub fn sample(slots: &[ParamSlot], seed: Option<u64>) -> Vec<f64> {
    match seed {
        None => slots.iter().map(|p| p.default).collect(),
        Some(seed) => {
            let mut rng = Rng::new(seed);
            slots.iter().map(|p| p.min + (p.max - p.min) * rng.unit()).collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_repeat_and_stay_in_range() {
        let slots = vec![ParamSlot { name: "a.shift".into(), min: -2.0, max: 3.0, default: 0.0 }; 4];
        let a = sample(&slots, Some(7));
        assert_eq!(a, sample(&slots, Some(7)));
        assert_ne!(a, sample(&slots, Some(8)));
        assert!(a.iter().all(|v| (-2.0..3.0).contains(v)));
        assert_eq!(sample(&slots, None), vec![0.0; 4]);
    }
}
