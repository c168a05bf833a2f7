//! The Intelligent Driver Model (Treiber, Hennecke, Helbing 2000), the one of the workspace:
//! the layout's roll-out follows with it, the runtime's NPC vehicles and its `idm` ego drive
//! with it (`tad_policy` re-exports it).

/// A speed below this is standing (SafeBench's stop-sign threshold), m/s; a desired speed
/// below it asks to stand.
pub const STANDING: f64 = 0.1;

/// IDM's parameters (note §4.2's urban defaults).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdmParams {
    /// `a`, m/s².
    pub max_accel: f64,
    /// `b`, m/s².
    pub comfort_decel: f64,
    /// `T`, s.
    pub headway: f64,
    /// `s0`, m.
    pub jam_gap: f64,
    /// `δ`.
    pub delta: f64,
    /// The hardest braking allowed, m/s² (positive).
    pub max_decel: f64,
}

impl Default for IdmParams {
    fn default() -> Self {
        IdmParams { max_accel: 2.0, comfort_decel: 3.0, headway: 1.5, jam_gap: 2.0, delta: 4.0, max_decel: 8.0 }
    }
}

impl IdmParams {
    /// IDM's acceleration at speed `v` towards `v0`, behind each obstacle `(gap m, its
    /// speed m/s)`: `a·[1 − (v/v0)^δ − (s*/s)²]` with `s* = s0 + max(0, vT + vΔv/(2√(ab)))`,
    /// the least over the obstacles, within `[−max_decel, max_accel]`. A desired speed
    /// below [`STANDING`] asks to stand: the free-road term brakes at `b`.
    pub fn accel(&self, v: f64, v0: f64, obstacles: impl IntoIterator<Item = (f64, f64)>) -> f64 {
        let IdmParams { max_accel: a, comfort_decel: b, headway, jam_gap, delta, max_decel } = *self;
        let v = v.max(0.0);
        let free = if v0 >= STANDING {
            a * (1.0 - (v / v0).powf(delta))
        } else if v > 0.0 {
            -b
        } else {
            0.0
        };
        let interaction = obstacles
            .into_iter()
            .map(|(gap, lead)| {
                let wanted = jam_gap + (v * headway + v * (v - lead) / (2.0 * (a * b).sqrt())).max(0.0);
                a * (wanted / gap.max(0.01)).powi(2)
            })
            .fold(0.0, f64::max);
        (free - interaction).clamp(-max_decel, a)
    }
}
