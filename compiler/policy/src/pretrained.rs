//! The pretrained driving models shipped inside the binary, driven by name like `idm`:
//! `ppo`, `sac` and `td3`. Each is an actor in `Learned`'s safetensors form (the
//! `kinematics` observation, 256 × 256 ReLU), made by `tad-train`: a DAgger warm start from
//! the idm driver, then its algorithm's own training on a seeded corpus of ordinary fitted
//! scenes. Beside each actor ship the critics it was kept with (`tad-train`'s
//! `Critics` file), which fine-tuning starts from, as ChatScene goes on from SafeBench's
//! checkpoint. `models/README.md` holds the command that reproduces each file byte for
//! byte, and what each achieves on held-out scenes.

use crate::{Learned, PolicyError};

/// A shipped model: its name, its actor's bytes and its critics' bytes.
#[derive(Clone, Copy, Debug)]
pub struct Pretrained {
    pub name: &'static str,
    pub bytes: &'static [u8],
    pub critics: &'static [u8],
}

/// Every shipped model, in the order tables list them.
pub const ALL: [Pretrained; 3] = [
    Pretrained {
        name: "ppo",
        bytes: include_bytes!("../models/ppo.safetensors"),
        critics: include_bytes!("../models/ppo.critics.safetensors"),
    },
    Pretrained {
        name: "sac",
        bytes: include_bytes!("../models/sac.safetensors"),
        critics: include_bytes!("../models/sac.critics.safetensors"),
    },
    Pretrained {
        name: "td3",
        bytes: include_bytes!("../models/td3.safetensors"),
        critics: include_bytes!("../models/td3.critics.safetensors"),
    },
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
