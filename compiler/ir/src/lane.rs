//! Lane indexes in TAD's convention (`spec/language.md` §4.3): `1..=n` in the ego's
//! direction counted from the left, `-1..=-n` in the opposite direction counted from the
//! left as its own traffic sees it; there is no lane 0.

use std::num::NonZeroI64;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Lane(NonZeroI64);

impl Lane {
    /// The lane of index `index`; `None` for 0.
    pub fn new(index: i64) -> Option<Lane> {
        NonZeroI64::new(index).map(Lane)
    }

    pub fn index(self) -> i64 {
        self.0.get()
    }

    /// In the opposite direction to the ego's.
    pub fn is_opposite(self) -> bool {
        self.index() < 0
    }

    /// The lane `by` lanes to the right (negative: to the left) as this lane's traffic
    /// sees it. Crossing the centre line moves into the other direction's lanes: left of
    /// lane 1 is lane -1, left of lane -1 is lane 1. The road's width is not checked.
    pub fn shift(self, by: i64) -> Lane {
        let lane = self.index();
        // positions 1, 2, ... rightwards in the ego's direction; 0, -1, ... beyond the centre
        let (position, direction) = if lane > 0 { (lane, 1) } else { (lane.saturating_add(1), -1) };
        let moved = position.saturating_add(by.saturating_mul(direction));
        let index = if moved >= 1 { moved } else { moved.saturating_sub(1) };
        Lane::new(index).unwrap_or(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lane(n: i64) -> Lane {
        Lane::new(n).unwrap()
    }

    #[test]
    fn shifting_crosses_the_centre_line() {
        assert_eq!(lane(1).shift(-1), lane(-1));
        assert_eq!(lane(1).shift(1), lane(2));
        assert_eq!(lane(-1).shift(-1), lane(1));
        assert_eq!(lane(-1).shift(1), lane(-2));
        assert_eq!(lane(3).shift(-1), lane(2));
        assert_eq!(lane(2).shift(0), lane(2));
        assert!(lane(-2).is_opposite() && !lane(2).is_opposite());
        assert_eq!(Lane::new(0), None);
    }

    #[test]
    fn extreme_shifts_do_not_overflow() {
        for n in [1, -1, i64::MAX, i64::MIN] {
            for by in [i64::MIN, -1, 1, i64::MAX] {
                assert_ne!(lane(n).shift(by).index(), 0);
            }
        }
    }
}
