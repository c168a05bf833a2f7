//! Parameters per run: each slot drawn uniformly from its range by a seeded generator
//! (`tad_ir::SplitMix64`, the workspace's one generator), so a seed always gives the same
//! values.

use tad_bytecode::ParamSlot;
use tad_ir::{Rng, SplitMix64};

/// The slots' values for a seed; `None` gives every slot its default.
pub fn sample(slots: &[ParamSlot], seed: Option<u64>) -> Vec<f64> {
    match seed {
        None => slots.iter().map(|p| p.default).collect(),
        Some(seed) => {
            let mut rng = SplitMix64::new(seed);
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
