//! A system message's keys and values kept on disk, as llama.cpp's `--prompt-cache` keeps a
//! prompt's state: a later process whose prompt starts with the same system message reads
//! them instead of prefilling it again (the translate prompt is about 3,000 tokens).
//!
//! A file is `DIR/KEY.kv`, `KEY` the sha256 of the format, the model's identity (the GGUF
//! file and the program, the adapter's weights, the kernels) and the tokens. The file is
//! untrusted: it repeats its tokens and shape, and ends with the sha256 of what precedes it;
//! anything that does not match the model and the prompt is ignored, and the prefix is
//! read as if there were no file. It is written under a temporary name and renamed, so a
//! reader never sees half a file. The decoder's outputs do not depend on the thread count,
//! so the kept values are the bits a prefill would compute.

use std::io::Write;
use std::path::PathBuf;

use sha2::{Digest, Sha256};

use crate::llama::Cache;

const MAGIC: &[u8; 8] = b"TADKV\x001\n";

/// Files a store keeps; the least recently written go first (the 1.5B model's translate
/// prompt is about 90 MB).
pub const KEPT: usize = 8;

/// Where the prefixes of one model (with its adapter) are kept.
#[derive(Clone, Debug)]
pub struct PromptStore {
    dir: PathBuf,
    identity: [u8; 32],
}

impl PromptStore {
    /// A store in `dir` for the model whose identity hashes to `identity`.
    pub fn new(dir: PathBuf, identity: [u8; 32]) -> PromptStore {
        PromptStore { dir, identity }
    }

    fn path(&self, tokens: &[u32]) -> PathBuf {
        let mut key = Sha256::new();
        key.update(MAGIC);
        key.update(self.identity);
        tokens.iter().for_each(|t| key.update(t.to_le_bytes()));
        let key: [u8; 32] = key.finalize().into();
        let hex: String = key.iter().map(|b| format!("{b:02x}")).collect();
        self.dir.join(format!("{hex}.kv"))
    }

    /// The cache of `tokens` for a model of `layers` layers and `width` values a position
    /// per layer, if a file holds exactly that.
    pub fn load(&self, tokens: &[u32], layers: usize, width: usize) -> Option<Cache> {
        let bytes = std::fs::read(self.path(tokens)).ok()?;
        decode(&bytes, &self.identity, tokens, layers, width)
    }

    /// Keeps the first `tokens.len()` positions of `cache` as the cache of `tokens`, in
    /// place of any file there (one that did not load).
    pub fn save(&self, tokens: &[u32], cache: &Cache) -> std::io::Result<()> {
        let path = self.path(tokens);
        std::fs::create_dir_all(&self.dir)?;
        let bytes = encode(&self.identity, tokens, cache);
        let temporary = path.with_extension(format!("kv.{}", std::process::id()));
        let written =
            std::fs::File::create(&temporary).and_then(|mut f| f.write_all(&bytes).and_then(|_| f.sync_all()));
        match written.and_then(|_| std::fs::rename(&temporary, &path)) {
            Ok(()) => {
                self.evict();
                Ok(())
            }
            Err(e) => {
                let _ = std::fs::remove_file(&temporary);
                Err(e)
            }
        }
    }

    /// Removes the oldest files beyond [`KEPT`].
    fn evict(&self) {
        let Ok(entries) = std::fs::read_dir(&self.dir) else { return };
        let mut files: Vec<(std::time::SystemTime, PathBuf)> = entries
            .flatten()
            .filter(|e| e.path().extension().is_some_and(|x| x == "kv"))
            .filter_map(|e| Some((e.metadata().ok()?.modified().ok()?, e.path())))
            .collect();
        files.sort();
        let surplus = files.len().saturating_sub(KEPT);
        for (_, path) in files.into_iter().take(surplus) {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// magic, identity, layers, width, n, the n tokens, each layer's keys then values (n ×
/// width halves each), then the sha256 of all of it.
fn encode(identity: &[u8; 32], tokens: &[u32], cache: &Cache) -> Vec<u8> {
    let n = tokens.len();
    let width = cache.width();
    let mut out = Vec::with_capacity(64 + 4 * n + 4 * cache.layers() * n * width);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(identity);
    for x in [cache.layers(), width, n] {
        out.extend_from_slice(&(x as u64).to_le_bytes());
    }
    tokens.iter().for_each(|t| out.extend_from_slice(&t.to_le_bytes()));
    for (k, v) in cache.layers_kv() {
        for half in k[..n * width].iter().chain(&v[..n * width]) {
            out.extend_from_slice(&half.to_le_bytes());
        }
    }
    let digest = Sha256::digest(&out);
    out.extend_from_slice(&digest);
    out
}

fn decode(bytes: &[u8], identity: &[u8; 32], tokens: &[u32], layers: usize, width: usize) -> Option<Cache> {
    let (body, digest) = bytes.split_at_checked(bytes.len().checked_sub(32)?)?;
    if Sha256::digest(body).as_slice() != digest {
        return None;
    }
    let rest = body.strip_prefix(MAGIC)?.strip_prefix(identity.as_slice())?;
    let (header, rest) = rest.split_at_checked(24)?;
    let field = |i: usize| u64::from_le_bytes(header[8 * i..8 * i + 8].try_into().unwrap()) as usize;
    let n = tokens.len();
    if (field(0), field(1), field(2)) != (layers, width, n) {
        return None;
    }
    let (kept, rest) = rest.split_at_checked(4 * n)?;
    let same = kept.chunks_exact(4).zip(tokens).all(|(b, t)| u32::from_le_bytes(b.try_into().unwrap()) == *t);
    if !same || rest.len() != 2 * 2 * layers * n * width {
        return None;
    }
    let halves = |chunk: &[u8]| chunk.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect();
    let mut chunks = rest.chunks_exact(2 * n * width).map(halves);
    let kv = (0..layers).map(|_| Some((chunks.next()?, chunks.next()?))).collect::<Option<Vec<_>>>()?;
    Some(Cache::from_layers(kv, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cache(layers: usize, width: usize, n: usize) -> Cache {
        let layer = |l: usize, s: u16| (0..n * width).map(|i| (i as u16).wrapping_mul(31) ^ s ^ l as u16).collect();
        Cache::from_layers((0..layers).map(|l| (layer(l, 1), layer(l, 2))).collect(), n)
    }

    #[test]
    fn a_kept_prefix_reads_back_and_anything_else_is_ignored() {
        let dir = std::env::temp_dir().join(format!("tad-prompts-{}", std::process::id()));
        let store = PromptStore::new(dir.clone(), [1; 32]);
        let tokens = [5, 6, 7];
        let kept = cache(2, 4, 3);
        store.save(&tokens, &kept).unwrap();
        let back = store.load(&tokens, 2, 4).expect("the kept prefix");
        assert_eq!(back.layers_kv().collect::<Vec<_>>(), kept.layers_kv().collect::<Vec<_>>());
        assert_eq!(back.len, 3);
        // another shape, other tokens, another model: nothing
        assert!(store.load(&tokens, 3, 4).is_none() && store.load(&tokens, 2, 8).is_none());
        assert!(store.load(&[5, 6, 8], 2, 4).is_none());
        assert!(PromptStore::new(dir.clone(), [2; 32]).load(&tokens, 2, 4).is_none());
        // a flipped bit, a cut file, garbage: ignored, never a panic
        let path = store.path(&tokens);
        let good = std::fs::read(&path).unwrap();
        for bad in [
            {
                let mut b = good.clone();
                b[good.len() / 2] ^= 1;
                b
            },
            good[..good.len() - 7].to_vec(),
            good[..10].to_vec(),
            Vec::new(),
            vec![0xff; 4096],
        ] {
            std::fs::write(&path, &bad).unwrap();
            assert!(store.load(&tokens, 2, 4).is_none());
        }
        // the file's own copy of the tokens is checked, not only its name
        let mut body = encode(&store.identity, &[5, 6, 9], &kept);
        body.truncate(body.len() - 32);
        let digest = Sha256::digest(&body);
        body.extend_from_slice(&digest);
        std::fs::write(&path, &body).unwrap();
        assert!(store.load(&tokens, 2, 4).is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
