//! The learning steps: SAC's and TD3's on a replay batch, PPO's on the rollout (see the
//! crate's header for each algorithm's losses).

use candle_core::{Device, Tensor};
use tad_ir::Rng;

use crate::nets::{ACT, deterministic, gaussian_log_prob, normals, q_fixed, q_values, sample_actions};
use crate::{Losses, Trainer};

/// TD3+BC's α: the RL term's weight against the demonstrations' once divided by mean |Q|.
const TD3_BC_ALPHA: f64 = 2.5;

/// A batch's columns as tensors.
struct Batch {
    obs: Tensor,
    act: Tensor,
    rew: Tensor,
    next: Tensor,
    done: Tensor,
}

impl Trainer {
    /// Replay rows as tensors.
    fn batch(&self, rows: &[&[f32]]) -> candle_core::Result<Batch> {
        let o = self.config.observation.width();
        let b = rows.len();
        let (mut obs, mut act, mut rew, mut next, mut done) = (
            Vec::with_capacity(b * o),
            Vec::with_capacity(b * ACT),
            Vec::with_capacity(b),
            Vec::with_capacity(b * o),
            Vec::with_capacity(b),
        );
        for t in rows {
            obs.extend_from_slice(&t[..o]);
            act.extend_from_slice(&t[o..o + ACT]);
            rew.push(t[o + ACT]);
            next.extend_from_slice(&t[o + ACT + 1..2 * o + ACT + 1]);
            done.push(t[2 * o + ACT + 1]);
        }
        let cpu = &Device::Cpu;
        Ok(Batch {
            obs: Tensor::from_vec(obs, (b, o), cpu)?,
            act: Tensor::from_vec(act, (b, ACT), cpu)?,
            rew: Tensor::from_vec(rew, (b, 1), cpu)?,
            next: Tensor::from_vec(next, (b, o), cpu)?,
            done: Tensor::from_vec(done, (b, 1), cpu)?,
        })
    }

    /// A batch: drawn with replacement from the replay, then, with colliding steps apart,
    /// their share of it drawn without replacement from theirs (all of them, if fewer).
    fn draw(&mut self) -> candle_core::Result<Batch> {
        let b = self.config.batch;
        let held = self.collisions.len();
        let apart = ((b as f64 * self.config.collision_share) as usize).min(held);
        let len = self.replay.len();
        let rows: Vec<usize> = (0..b - apart).map(|_| self.rng.below(len)).collect();
        let mut pool: Vec<usize> = (0..held).collect();
        for i in 0..apart {
            let j = i + self.rng.below(held - i);
            pool.swap(i, j);
        }
        let rows: Vec<&[f32]> = rows
            .iter()
            .map(|&i| self.replay.row(i))
            .chain(pool[..apart].iter().map(|&i| self.collisions.row(i)))
            .collect();
        self.batch(&rows)
    }

    /// Whether this learning step may move the actor.
    fn actor_moves(&self) -> bool {
        self.updates >= self.config.critic_warmup as u64
    }

    /// The demonstrations' term, `bc_weight · MSE(tanh(mu(o)), a)` on a batch of them;
    /// `None` without a weight or demonstrations.
    fn demo_loss(&mut self) -> candle_core::Result<Option<Tensor>> {
        let width = self.config.observation.width();
        let n = self.demos.len() / (width + ACT);
        if self.config.bc_weight <= 0.0 || n == 0 {
            return Ok(None);
        }
        let b = self.config.batch;
        let (mut obs, mut act) = (Vec::with_capacity(b * width), Vec::with_capacity(b * ACT));
        for _ in 0..b {
            let i = self.rng.below(n);
            let row = &self.demos[i * (width + ACT)..(i + 1) * (width + ACT)];
            obs.extend_from_slice(&row[..width]);
            act.extend_from_slice(&row[width..]);
        }
        let obs = Tensor::from_vec(obs, (b, width), &Device::Cpu)?;
        let act = Tensor::from_vec(act, (b, ACT), &Device::Cpu)?;
        let mse = (deterministic(&self.actor, &obs)? - act)?.sqr()?.mean_all()?;
        Ok(Some(mse.affine(self.config.bc_weight, 0.0)?))
    }

    /// An actor's RL loss `−Q`-like term with the demonstrations added: scaled by
    /// `TD3_BC_ALPHA / mean |q|` when there are some.
    fn with_demos(&mut self, rl: Tensor, q: &Tensor) -> candle_core::Result<Tensor> {
        match self.demo_loss()? {
            None => Ok(rl),
            Some(demo) => {
                let scale = q.abs()?.mean_all()?.to_scalar::<f32>()?.max(1e-6);
                rl.affine(TD3_BC_ALPHA / f64::from(scale), 0.0)? + demo
            }
        }
    }

    fn refresh_plain(&mut self) -> candle_core::Result<()> {
        self.plain = crate::nets::PlainActor::of(&self.actor).map_err(|e| candle_core::Error::Msg(e.to_string()))?;
        Ok(())
    }

    pub(crate) fn sac_update(&mut self) -> candle_core::Result<Losses> {
        let Batch { obs, act, rew, next, done } = self.draw()?;
        let b = self.config.batch;
        let cpu = &Device::Cpu;
        let eps_next = Tensor::from_vec(normals(&mut self.rng, b * ACT), (b, ACT), cpu)?;
        let eps_now = Tensor::from_vec(normals(&mut self.rng, b * ACT), (b, ACT), cpu)?;
        let (gamma, alpha) = (self.config.gamma, self.config.alpha);
        let c = &self.critics;

        // critics: r + γ(1 − d)(min Q_targ(o', ã') − α log π(ã'|o')), held fixed
        let (a2, logp2) = sample_actions(&self.actor, &next, &eps_next)?;
        let (t1, t2) = (q_fixed(c.get("q1_target"), &next, &a2)?, q_fixed(c.get("q2_target"), &next, &a2)?);
        let soft = (t1.minimum(&t2)? - logp2.affine(alpha, 0.0)?)?;
        let backup = (rew + (done.affine(-gamma, gamma)? * soft)?)?.detach();
        let (c1, c2) = q_values(c.get("q1"), c.get("q2"), &obs, &act)?;
        let critic_loss = ((c1 - &backup)?.sqr()?.mean_all()? + (c2 - &backup)?.sqr()?.mean_all()?)?;
        self.critic_opt.minimise(&critic_loss)?;

        // actor: α log π(ã|o) − min Q(o, ã), on the critics just updated (held fixed)
        let (a, logp) = sample_actions(&self.actor, &obs, &eps_now)?;
        let mut actor_loss = 0.0;
        if self.actor_moves() {
            let (p1, p2) = (q_fixed(c.get("q1"), &obs, &a)?, q_fixed(c.get("q2"), &obs, &a)?);
            let q = p1.minimum(&p2)?;
            let loss = (logp.affine(alpha, 0.0)? - &q)?.mean_all()?;
            let loss = self.with_demos(loss, &q.detach())?;
            self.actor_opt.minimise(&loss)?;
            actor_loss = loss.to_scalar::<f32>()?;
        }
        let (polyak, c) = (self.config.polyak, &self.critics);
        c.get("q1_target").polyak_from(c.get("q1"), polyak)?;
        c.get("q2_target").polyak_from(c.get("q2"), polyak)?;
        self.refresh_plain()?;
        self.updates += 1;
        Ok(Losses {
            critic: critic_loss.to_scalar::<f32>()?,
            actor: actor_loss,
            entropy: -logp.mean_all()?.to_scalar::<f32>()?,
        })
    }

    pub(crate) fn td3_update(&mut self) -> candle_core::Result<Losses> {
        let Batch { obs, act, rew, next, done } = self.draw()?;
        let b = self.config.batch;
        let (gamma, polyak) = (self.config.gamma, self.config.polyak);
        let clip = self.config.noise_clip;
        let noise: Vec<f32> = normals(&mut self.rng, b * ACT)
            .into_iter()
            .map(|e| (f64::from(e) * self.config.target_noise).clamp(-clip, clip) as f32)
            .collect();
        let noise = Tensor::from_vec(noise, (b, ACT), &Device::Cpu)?;
        let c = &self.critics;

        // critics: r + γ(1 − d) min Q_targ(o', clip(π_targ(o') + clip(ε)))
        let a2 = (c.get("actor_target").forward_fixed(&next)?[0].tanh()? + noise)?.clamp(-1f32, 1f32)?;
        let (t1, t2) = (q_fixed(c.get("q1_target"), &next, &a2)?, q_fixed(c.get("q2_target"), &next, &a2)?);
        let backup = (rew + (done.affine(-gamma, gamma)? * t1.minimum(&t2)?)?)?.detach();
        let (c1, c2) = q_values(c.get("q1"), c.get("q2"), &obs, &act)?;
        let critic_loss = ((c1 - &backup)?.sqr()?.mean_all()? + (c2 - &backup)?.sqr()?.mean_all()?)?;
        self.critic_opt.minimise(&critic_loss)?;
        self.updates += 1;

        // the actor and the targets, every `policy_delay` steps
        let mut actor_loss = 0.0;
        if self.updates.is_multiple_of(self.config.policy_delay as u64) {
            if self.actor_moves() {
                let a = deterministic(&self.actor, &obs)?;
                // TD3's actor follows the first critic only (held fixed)
                let p1 = q_fixed(c.get("q1"), &obs, &a)?;
                let loss = p1.neg()?.mean_all()?;
                let loss = self.with_demos(loss, &p1.detach())?;
                self.actor_opt.minimise(&loss)?;
                actor_loss = loss.to_scalar::<f32>()?;
            }
            let c = &self.critics;
            c.get("q1_target").polyak_from(c.get("q1"), polyak)?;
            c.get("q2_target").polyak_from(c.get("q2"), polyak)?;
            c.get("actor_target").polyak_from(&self.actor, polyak)?;
            self.refresh_plain()?;
        }
        Ok(Losses { critic: critic_loss.to_scalar::<f32>()?, actor: actor_loss, entropy: 0.0 })
    }

    /// PPO on the whole rollout: advantages by GAE, then `epochs` passes of minibatches.
    pub(crate) fn ppo_update(&mut self) -> candle_core::Result<Losses> {
        let n = self.replay.len();
        let all: Vec<usize> = (0..n).collect();
        let rows: Vec<&[f32]> = all.iter().map(|&i| self.replay.row(i)).collect();
        let Batch { obs, act, rew, next, done } = self.batch(&rows)?;
        let v = self.critics.get("v");
        let values = v.forward(&obs)?.remove(0).flatten_all()?.to_vec1::<f32>()?;
        let next_values = v.forward(&next)?.remove(0).flatten_all()?.to_vec1::<f32>()?;
        let logp_old = gaussian_log_prob(&self.actor, &obs, &act)?.detach();
        let (rew, done) = (rew.flatten_all()?.to_vec1::<f32>()?, done.flatten_all()?.to_vec1::<f32>()?);
        let end_column = self.replay.width - 1;
        let (gamma, lambda) = (self.config.gamma as f32, self.config.lambda as f32);
        let (mut adv, mut gae) = (vec![0f32; n], 0f32);
        for i in (0..n).rev() {
            let live = 1.0 - done[i];
            let delta = rew[i] + gamma * next_values[i] * live - values[i];
            let ends = self.replay.row(i)[end_column] > 0.5;
            gae = if ends { delta } else { delta + gamma * lambda * live * gae };
            adv[i] = gae;
        }
        let returns: Vec<f32> = adv.iter().zip(&values).map(|(a, v)| a + v).collect();
        let mean = adv.iter().sum::<f32>() / n as f32;
        let sd = (adv.iter().map(|a| (a - mean).powi(2)).sum::<f32>() / n as f32).sqrt().max(1e-8);
        let adv: Vec<f32> = adv.iter().map(|a| (a - mean) / sd).collect();
        let cpu = &Device::Cpu;
        let adv = Tensor::from_vec(adv, (n, 1), cpu)?;
        let returns = Tensor::from_vec(returns, (n, 1), cpu)?;

        let clip = self.config.clip;
        let mut last = Losses { critic: 0.0, actor: 0.0, entropy: 0.0 };
        let mut order = all;
        for _ in 0..self.config.epochs {
            self.rng.shuffle(&mut order);
            for chunk in order.chunks(self.config.batch) {
                let idx = Tensor::from_vec(chunk.iter().map(|&i| i as u32).collect::<Vec<_>>(), chunk.len(), cpu)?;
                let pick = |t: &Tensor| t.index_select(&idx, 0);
                let (o, u, a, r) = (pick(&obs)?, pick(&act)?, pick(&adv)?, pick(&returns)?);
                let value = self.critics.get("v").forward(&o)?.remove(0);
                let value_loss = (value - r)?.sqr()?.mean_all()?;
                self.critic_opt.minimise(&value_loss)?;
                last.critic = value_loss.to_scalar::<f32>()?;
                if self.actor_moves() {
                    let logp = gaussian_log_prob(&self.actor, &o, &u)?;
                    let ratio = (logp.clone() - pick(&logp_old)?)?.exp()?;
                    let unclipped = (&ratio * &a)?;
                    let clipped = (ratio.clamp(1.0 - clip, 1.0 + clip)? * &a)?;
                    let loss = unclipped.minimum(&clipped)?.mean_all()?.neg()?;
                    // advantages are normalised: the demonstrations add at their weight
                    let loss = match self.demo_loss()? {
                        Some(demo) => (loss + demo)?,
                        None => loss,
                    };
                    self.actor_opt.minimise(&loss)?;
                    last.actor = loss.to_scalar::<f32>()?;
                    last.entropy = -logp.mean_all()?.to_scalar::<f32>()?;
                }
            }
        }
        self.refresh_plain()?;
        self.updates += 1;
        Ok(last)
    }
}

#[cfg(test)]
mod tests {
    use crate::{Config, Trainer};

    /// A trainer whose replay holds `plain` rows (first value `i`) and whose colliding
    /// steps' ring holds `collided` (first value `−1 − i`).
    fn filled(share: f64, plain: usize, collided: usize) -> Trainer {
        let config = Config { hidden: vec![4], batch: 20, buffer: 1000, collision_share: share, ..Config::default() };
        let mut t = Trainer::new(config).expect("a trainer");
        let w = t.replay.width;
        for i in 0..plain {
            t.replay.push(1000, &[vec![i as f32], vec![0.0; w - 1]].concat());
        }
        for i in 0..collided {
            t.collisions.push(10, &[vec![-1.0 - i as f32], vec![0.0; w - 1]].concat());
        }
        t
    }

    /// The colliding rows of a drawn batch, by their first value.
    fn colliding(t: &mut Trainer) -> Vec<i64> {
        let obs = t.draw().expect("a batch").obs.to_vec2::<f32>().expect("values");
        assert_eq!(obs.len(), 20);
        let mut hits: Vec<i64> = obs.iter().map(|r| r[0] as i64).filter(|&v| v < 0).collect();
        hits.sort_unstable();
        hits
    }

    #[test]
    fn a_fifth_of_each_batch_is_colliding_steps_each_drawn_once() {
        let mut t = filled(0.2, 50, 6);
        for _ in 0..20 {
            let hits = colliding(&mut t);
            assert_eq!(hits.len(), 4, "20 / 5 colliding rows");
            assert!(hits.windows(2).all(|w| w[0] < w[1]), "without replacement: {hits:?}");
        }
        // fewer held than the share: all of them
        assert_eq!(colliding(&mut filled(0.2, 50, 2)), vec![-2, -1]);
        // without a share, one ring
        assert!(colliding(&mut filled(0.0, 50, 6)).is_empty());
    }
}
