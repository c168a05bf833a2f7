//! Parameters: a value a scenario states exactly, as a range or as a choice
//! (`spec/language.md` §4.1, `spec/ir.md` §5.1).
//!
//! A field that takes a parameter is a `Field<Param<T>>`. Consumers that want one value
//! take [`Param::nominal`] (the midpoint of a range, the first name of a choice) or
//! [`Param::fixed`] (only a single value); a parameter search samples with
//! [`Param::sample`] and a seeded [`Rng`] (the IR has no global randomness).

use crate::entries::Named;
use crate::quantity::{Metres, MetresPerSecond, Seconds};

/// A value, a range of values, or a choice among values.
#[derive(Clone, Debug, PartialEq)]
pub enum Param<T> {
    /// One value: `30 km/h`, `go_forward`.
    Fixed(T),
    /// Every value from `min` to `max`, both included (`min <= max`): `30..40 km/h`, `3..5`.
    Range { min: T, max: T },
    /// One of these (at least one, each once): `go_forward | turn_left`.
    Choice(Vec<T>),
}

/// What a parameter can hold: its values can be interpolated (numbers) or not (names,
/// whose ranges do not exist: only choices).
pub trait ParamValue: Clone {
    /// The value at `t` (0 to 1) from `min` to `max`.
    fn between(min: &Self, max: &Self, t: f64) -> Self;
}

macro_rules! si_param {
    ($($t:ident),*) => {$(
        impl ParamValue for $t {
            fn between(min: &Self, max: &Self, t: f64) -> Self {
                $t(min.0 + (max.0 - min.0) * t)
            }
        }
    )*};
}
si_param!(MetresPerSecond, Metres, Seconds);

impl ParamValue for f64 {
    fn between(min: &Self, max: &Self, t: f64) -> Self {
        min + (max - min) * t
    }
}

impl ParamValue for i64 {
    /// Whole numbers: `t` picks one of `min..=max` evenly; the midpoint rounds up.
    fn between(min: &Self, max: &Self, t: f64) -> Self {
        let span = (*max - *min).max(0) as f64 + 1.0;
        (*min + (t * span).floor() as i64).min(*max)
    }
}

impl<K: Clone> ParamValue for Named<K> {
    /// Names have no ranges: the lower end.
    fn between(min: &Self, _max: &Self, _t: f64) -> Self {
        min.clone()
    }
}

impl<T> Param<T> {
    /// The single value, `None` for a range or a choice.
    pub fn fixed(&self) -> Option<&T> {
        match self {
            Param::Fixed(v) => Some(v),
            _ => None,
        }
    }

    pub fn is_fixed(&self) -> bool {
        matches!(self, Param::Fixed(_))
    }

    /// The values a choice (or a single value) lists; a range's two ends.
    pub fn values(&self) -> Vec<&T> {
        match self {
            Param::Fixed(v) => vec![v],
            Param::Range { min, max } => vec![min, max],
            Param::Choice(options) => options.iter().collect(),
        }
    }

    pub fn map<U>(self, mut f: impl FnMut(T) -> U) -> Param<U> {
        match self {
            Param::Fixed(v) => Param::Fixed(f(v)),
            Param::Range { min, max } => Param::Range { min: f(min), max: f(max) },
            Param::Choice(options) => Param::Choice(options.into_iter().map(f).collect()),
        }
    }
}

impl<T: ParamValue> Param<T> {
    /// The value a consumer that needs one takes: the value, a range's midpoint (rounded
    /// up for whole numbers), a choice's first.
    pub fn nominal(&self) -> T {
        match self {
            Param::Fixed(v) => v.clone(),
            Param::Range { min, max } => T::between(min, max, 0.5),
            Param::Choice(options) => options[0].clone(),
        }
    }

    /// One value drawn from `rng`: uniform over a range (whole numbers: each equally
    /// likely), one of a choice with equal chances.
    pub fn sample(&self, rng: &mut impl Rng) -> T {
        match self {
            Param::Fixed(v) => v.clone(),
            Param::Range { min, max } => T::between(min, max, rng.unit()),
            Param::Choice(options) => {
                let i = ((rng.unit() * options.len() as f64) as usize).min(options.len() - 1);
                options[i].clone()
            }
        }
    }
}

impl<T: ParamValue + PartialOrd> Param<T> {
    /// The least value it can take.
    pub fn min(&self) -> T {
        match self {
            Param::Fixed(v) | Param::Range { min: v, .. } => v.clone(),
            Param::Choice(options) => {
                options.iter().fold(options[0].clone(), |m, v| if *v < m { v.clone() } else { m })
            }
        }
    }

    /// The greatest value it can take.
    pub fn max(&self) -> T {
        match self {
            Param::Fixed(v) | Param::Range { max: v, .. } => v.clone(),
            Param::Choice(options) => {
                options.iter().fold(options[0].clone(), |m, v| if *v > m { v.clone() } else { m })
            }
        }
    }
}

pub use tad_base::{Rng, SplitMix64};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_min_max() {
        let speed = Param::Range { min: MetresPerSecond(8.0), max: MetresPerSecond(12.0) };
        assert_eq!(speed.nominal(), MetresPerSecond(10.0));
        assert_eq!(speed.min(), MetresPerSecond(8.0));
        assert_eq!(speed.max(), MetresPerSecond(12.0));
        let count = Param::Range { min: 3i64, max: 4 };
        assert_eq!(count.nominal(), 4);
        assert_eq!(Param::Range { min: 3i64, max: 5 }.nominal(), 4);
        assert_eq!(Param::Fixed(7i64).nominal(), 7);
        let choice = Param::Choice(vec![3i64, 1, 2]);
        assert_eq!((choice.nominal(), choice.min(), choice.max()), (3, 1, 3));
    }

    #[test]
    fn sampling_is_seeded_and_stays_in_bounds() {
        let count = Param::Range { min: 3i64, max: 5 };
        let speed = Param::Range { min: 8.0f64, max: 12.0 };
        let mut rng = SplitMix64::new(7);
        let counts: Vec<i64> = (0..200).map(|_| count.sample(&mut rng)).collect();
        assert!(counts.iter().all(|c| (3..=5).contains(c)));
        assert!((3..=5).all(|c| counts.contains(&c)), "every count is drawn");
        let speeds: Vec<f64> = (0..200).map(|_| speed.sample(&mut rng)).collect();
        assert!(speeds.iter().all(|s| (8.0..=12.0).contains(s)));
        let again: Vec<i64> = {
            let mut rng = SplitMix64::new(7);
            (0..200).map(|_| count.sample(&mut rng)).collect()
        };
        assert_eq!(counts, again, "the same seed draws the same values");
        let choice = Param::Choice(vec!["a", "b"].into_iter().map(String::from).collect::<Vec<_>>());
        let _ = choice.values();
    }
}
