//! Quantities in SI units. Lowering keeps the unit a value was written in; the IR converts
//! once, so `20 mph` and `32.2 km/h` are the same [`MetresPerSecond`].

/// A speed in m/s.
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct MetresPerSecond(pub f64);

impl MetresPerSecond {
    pub fn km_per_hour(self) -> f64 {
        self.0 * 3.6
    }
}

/// A length in m.
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct Metres(pub f64);

/// A time in s.
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct Seconds(pub f64);
