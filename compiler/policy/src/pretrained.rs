//! The pretrained driving models shipped inside the binary, driven by name like `idm`:
//! `ppo`, `sac` and `td3`. Each is an actor in `Learned`'s safetensors form (the `state`
//! observation, 256 × 256 ReLU), made by `tad-train`: a DAgger warm start from the idm
//! driver, then its algorithm's own training on a seeded corpus of ordinary fitted
//! scenes. `models/README.md` holds the command that reproduces each file byte for byte,
//! and what each achieves on held-out scenes.

use crate::{Learned, PolicyError};

/// A shipped model: its name and its file's bytes.
#[derive(Clone, Copy, Debug)]
pub struct Pretrained {
    pub name: &'static str,
    pub bytes: &'static [u8],
}

/// Every shipped model, in the order tables list them.
pub const ALL: [Pretrained; 3] = [
    Pretrained { name: "ppo", bytes: include_bytes!("../models/ppo.safetensors") },
    Pretrained { name: "sac", bytes: include_bytes!("../models/sac.safetensors") },
    Pretrained { name: "td3", bytes: include_bytes!("../models/td3.safetensors") },
];

/// The shipped model called `name`.
pub fn find(name: &str) -> Option<Pretrained> {
    ALL.into_iter().find(|m| m.name == name)
}

impl Pretrained {
    /// The actor, named as the command line names it.
    pub fn load(self) -> Result<Learned, PolicyError> {
        Learned::from_bytes(self.bytes, self.name)
    }
}
