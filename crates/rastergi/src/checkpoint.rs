//! Checkpoints: a render's state on disk, to resume it (later, or on another machine) and to
//! merge renders of the same image made with different seeds.
//!
//! A checkpoint holds what the next iteration needs to continue the same random sequence — the
//! film's sums and their odd half ([`FilmState`]), the iteration count, the seed, the photon
//! pass and how far into it the render is, the gather the first iterations chose — and what
//! it is a render of: a hash of the scene as rendered (geometry, materials, textures, lights,
//! sky, camera) and the settings other than the seed, as text, so a mismatch is named.
//!
//! Every random choice of iteration i depends on (seed, i) alone (pixel jitter, light samples,
//! gather directions) or on (seed, photon pass) (the photons), and the film adds iteration
//! after iteration in the same order, so a resumed render gives the uninterrupted render's
//! sums bit for bit (tests/checkpoints.rs).
//!
//! # Format (little-endian)
//!
//! ```text
//!   magic "RGICKPT\0", version u32 = 1
//!   scene hash u64, seed u32
//!   settings: byte length u32, UTF-8 "key=value" lines
//!   photon pass u32, iterations into it u32, gather method u32, gather directions u32
//!   width u32, height u32, samples u32, odd-half samples u32
//!   float count u64, sums (f32 × count), odd half (f32 × count)
//!   XXH3-64 of everything above, u64
//! ```
//!
//! Files are written to a temporary file in the same directory and renamed over the target,
//! so a checkpoint on disk is always whole; a truncated or altered one fails its hash.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::gather::{GatherDirections, GatherMethod};
use crate::passes::film::FilmState;

const MAGIC: &[u8; 8] = b"RGICKPT\0";
const VERSION: u32 = 1;

/// Where a render stands besides its film.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Progress {
    /// The photon pass of the last iteration (0-based) and its iterations so far.
    pub photon_pass: u32,
    pub iterations_in_pass: u32,
    /// The gather `Auto` chose on the first iterations (`None`: not chosen yet, or fixed by
    /// the settings).
    pub gather: Option<(GatherMethod, GatherDirections)>,
}

/// A render's state: see the module's notes.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub scene_hash: u64,
    pub seed: u32,
    /// The settings other than the seed, `(key, value)` in a fixed order.
    pub settings: Vec<(String, String)>,
    pub progress: Progress,
    pub film: FilmState,
}

fn checkpoint_error(path: &Path, message: impl Into<String>) -> Error {
    Error::CheckpointFile { path: path.to_path_buf(), message: message.into() }
}

fn gather_code(g: Option<(GatherMethod, GatherDirections)>) -> (u32, u32) {
    match g {
        None => (0, 0),
        Some((m, d)) => (
            match m {
                GatherMethod::Auto => 0,
                GatherMethod::Raster => 1,
                GatherMethod::Lists => 2,
                GatherMethod::Trace => 3,
            },
            match d {
                GatherDirections::PerPixel => 0,
                GatherDirections::Shared => 1,
            },
        ),
    }
}

fn gather_from_code(m: u32, d: u32) -> Option<Option<(GatherMethod, GatherDirections)>> {
    let method = match m {
        0 => return Some(None),
        1 => GatherMethod::Raster,
        2 => GatherMethod::Lists,
        3 => GatherMethod::Trace,
        _ => return None,
    };
    let directions = match d {
        0 => GatherDirections::PerPixel,
        1 => GatherDirections::Shared,
        _ => return None,
    };
    Some(Some((method, directions)))
}

impl Checkpoint {
    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(64 + 8 * self.film.sums.len());
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&VERSION.to_le_bytes());
        b.extend_from_slice(&self.scene_hash.to_le_bytes());
        b.extend_from_slice(&self.seed.to_le_bytes());
        let text: String = self.settings.iter().map(|(k, v)| format!("{k}={v}\n")).collect();
        b.extend_from_slice(&(text.len() as u32).to_le_bytes());
        b.extend_from_slice(text.as_bytes());
        let (m, d) = gather_code(self.progress.gather);
        let f = &self.film;
        for v in [self.progress.photon_pass, self.progress.iterations_in_pass, m, d, f.width, f.height, f.samples] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&f.half_samples.to_le_bytes());
        b.extend_from_slice(&(f.sums.len() as u64).to_le_bytes());
        b.extend_from_slice(bytemuck::cast_slice(&f.sums));
        b.extend_from_slice(bytemuck::cast_slice(&f.half));
        let hash = xxhash_rust::xxh3::xxh3_64(&b);
        b.extend_from_slice(&hash.to_le_bytes());
        b
    }

    /// Parses a checkpoint file's bytes; `path` names it in errors.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<Checkpoint> {
        let bad = |what: &str| {
            checkpoint_error(
                path,
                format!("{what}; the file is not a whole rastergi checkpoint (truncated or damaged)"),
            )
        };
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(checkpoint_error(path, "not a rastergi checkpoint (no RGICKPT header)"));
        }
        if bytes.len() < 8 + 4 + 8 {
            return Err(bad("too short"));
        }
        let (body, tail) = bytes.split_at(bytes.len() - 8);
        let stored = u64::from_le_bytes(tail.try_into().expect("8 bytes"));
        let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if version != VERSION {
            return Err(checkpoint_error(
                path,
                format!("checkpoint format version {version}; this rastergi reads version {VERSION}"),
            ));
        }
        if xxhash_rust::xxh3::xxh3_64(body) != stored {
            return Err(bad("its checksum does not match its contents"));
        }
        let mut r = Reader { bytes: body, at: 12 };
        let scene_hash = r.u64().ok_or_else(|| bad("too short"))?;
        let seed = r.u32().ok_or_else(|| bad("too short"))?;
        let text_len = r.u32().ok_or_else(|| bad("too short"))? as usize;
        let text = r.take(text_len).ok_or_else(|| bad("too short"))?;
        let text = std::str::from_utf8(text).map_err(|_| bad("its settings are not text"))?;
        // Lines end at '\n' alone, as written: a '\r' before one is part of its value.
        let settings = text
            .split_terminator('\n')
            .map(|l| {
                l.split_once('=').map(|(k, v)| (k.to_owned(), v.to_owned())).ok_or_else(|| bad("bad settings line"))
            })
            .collect::<Result<Vec<_>>>()?;
        let mut u = [0u32; 8];
        for v in &mut u {
            *v = r.u32().ok_or_else(|| bad("too short"))?;
        }
        let [photon_pass, iterations_in_pass, m, d, width, height, samples, half_samples] = u;
        let gather = gather_from_code(m, d).ok_or_else(|| bad("unknown gather code"))?;
        let count = r.u64().ok_or_else(|| bad("too short"))? as usize;
        let expected = (width as u64 * height as u64).checked_mul(4 * crate::passes::film::COMPONENTS);
        if expected != Some(count as u64) {
            return Err(bad("its film size does not match its image size"));
        }
        let floats = |r: &mut Reader| -> Option<Vec<f32>> {
            let raw = r.take(count.checked_mul(4)?)?;
            Some(raw.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes"))).collect())
        };
        let sums = floats(&mut r).ok_or_else(|| bad("too short"))?;
        let half = floats(&mut r).ok_or_else(|| bad("too short"))?;
        if r.at != body.len() {
            return Err(bad("trailing bytes"));
        }
        if half_samples > samples {
            return Err(bad("inconsistent sample counts"));
        }
        Ok(Checkpoint {
            scene_hash,
            seed,
            settings,
            progress: Progress { photon_pass, iterations_in_pass, gather },
            film: FilmState { width, height, samples, half_samples, sums, half },
        })
    }

    /// Reads a checkpoint file.
    pub fn read(path: &Path) -> Result<Checkpoint> {
        let bytes = std::fs::read(path).map_err(|e| checkpoint_error(path, format!("cannot read it: {e}")))?;
        Checkpoint::from_bytes(path, &bytes)
    }

    /// Writes the checkpoint to `path` atomically (a temporary file renamed over it).
    pub fn write(&self, path: &Path) -> Result<()> {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut tmp = tempfile::Builder::new()
            .prefix(".rastergi-")
            .suffix(".ckpt")
            .tempfile_in(&dir)
            .map_err(|e| checkpoint_error(path, format!("cannot create a file in {}: {e}", dir.display())))?;
        use std::io::Write;
        tmp.write_all(&self.to_bytes())
            .and_then(|_| tmp.as_file().sync_all())
            .map_err(|e| checkpoint_error(path, format!("cannot write it: {e}")))?;
        tmp.persist(path).map_err(|e| checkpoint_error(path, format!("cannot replace the file: {}", e.error)))?;
        Ok(())
    }

    /// Checks that the checkpoint `path` is of this scene and these settings (the seed
    /// included where `seed` is given), naming what differs.
    pub fn check_matches(
        &self,
        path: &Path,
        scene_hash: u64,
        settings: &[(String, String)],
        seed: Option<u32>,
    ) -> Result<()> {
        if let (Some(seeds), Some(_)) = (self.merged_seeds(), seed) {
            return Err(checkpoint_error(
                path,
                format!(
                    "it is a merge of the renders of seeds {}: it cannot be resumed (merge more renders into it instead)",
                    seeds.iter().map(u32::to_string).collect::<Vec<_>>().join(", ")
                ),
            ));
        }
        if self.scene_hash != scene_hash {
            return Err(checkpoint_error(
                path,
                "it is a render of another scene or camera; give the scene file and camera options it was rendered with",
            ));
        }
        let differences = settings_differences(&self.own_settings(), settings);
        if !differences.is_empty() {
            return Err(checkpoint_error(
                path,
                format!("it was rendered with other settings ({}); give the same options", differences.join(", ")),
            ));
        }
        if let Some(seed) = seed.filter(|&s| s != self.seed) {
            return Err(checkpoint_error(
                path,
                format!("it was rendered with --seed {}, not {seed}; give --seed {}", self.seed, self.seed),
            ));
        }
        Ok(())
    }
}

const MERGED_SEEDS: &str = "merged-seeds";

impl Checkpoint {
    /// The seeds of the renders merged into this one (`None`: one render's).
    pub fn merged_seeds(&self) -> Option<Vec<u32>> {
        let (_, v) = self.settings.iter().find(|(k, _)| k == MERGED_SEEDS)?;
        Some(v.split(',').filter_map(|s| s.parse().ok()).collect())
    }

    /// The seeds whose renders this checkpoint holds.
    pub fn seeds(&self) -> Vec<u32> {
        self.merged_seeds().unwrap_or_else(|| vec![self.seed])
    }

    /// The settings, without the record of a merge.
    fn own_settings(&self) -> Vec<(String, String)> {
        self.settings.iter().filter(|(k, _)| k != MERGED_SEEDS).cloned().collect()
    }
}

/// "key: checkpoint's value (here: value)" for each setting that differs.
fn settings_differences(a: &[(String, String)], b: &[(String, String)]) -> Vec<String> {
    let mut out = Vec::new();
    for (k, va) in a {
        match b.iter().find(|(kb, _)| kb == k) {
            Some((_, vb)) if vb == va => {}
            Some((_, vb)) => out.push(format!("{k} {va}, here {vb}")),
            None => out.push(format!("{k} {va}, here none")),
        }
    }
    for (k, vb) in b {
        if !a.iter().any(|(ka, _)| ka == k) {
            out.push(format!("{k} none, here {vb}"));
        }
    }
    out
}

/// Merges checkpoints of one image rendered with different seeds: the sums add, so the mean
/// weighs each render by its iteration count — in expectation the image of one render as
/// long as all of them (for the photon map, of renders whose passes each had their own
/// photons; see docs/user-guide.md, "Merging"). Refuses checkpoints of different scenes or settings and two of
/// the same seed (the same random numbers: not independent).
pub fn merge(paths: &[PathBuf]) -> Result<Checkpoint> {
    let (first, rest) = paths.split_first().ok_or_else(|| Error::Checkpoint("nothing to merge".into()))?;
    let mut merged = Checkpoint::read(first)?;
    let mut seeds: Vec<(u32, PathBuf)> = merged.seeds().into_iter().map(|s| (s, first.clone())).collect();
    let settings = merged.own_settings();
    for path in rest {
        let c = Checkpoint::read(path)?;
        c.check_matches(path, merged.scene_hash, &settings, None).map_err(|e| match e {
            Error::CheckpointFile { path, message } => Error::CheckpointFile {
                path,
                message: format!("{message} (as {})", first.display()).replace("here", "in the first"),
            },
            e => e,
        })?;
        for seed in c.seeds() {
            if let Some((_, other)) = seeds.iter().find(|(s, _)| *s == seed) {
                return Err(checkpoint_error(
                    path,
                    format!(
                        "it holds seed {seed} like {}: the same random numbers, not an independent render; render each with its own --seed",
                        other.display()
                    ),
                ));
            }
            seeds.push((seed, path.clone()));
        }
        merged.film.add(&c.film);
    }
    let list = seeds.iter().map(|(s, _)| s.to_string()).collect::<Vec<_>>().join(",");
    merged.settings = settings;
    merged.settings.push((MERGED_SEEDS.to_owned(), list));
    Ok(merged)
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let end = self.at.checked_add(n)?;
        let s = self.bytes.get(self.at..end)?;
        self.at = end;
        Some(s)
    }

    fn u32(&mut self) -> Option<u32> {
        self.take(4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }

    fn u64(&mut self) -> Option<u64> {
        self.take(8).map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Checkpoint {
        let n = 4 * crate::passes::film::COMPONENTS as usize * 6;
        Checkpoint {
            scene_hash: 0x1234_5678_9abc_def0,
            seed: 7,
            settings: vec![("width".into(), "3".into()), ("photons".into(), "100".into())],
            progress: Progress {
                photon_pass: 2,
                iterations_in_pass: 5,
                gather: Some((GatherMethod::Trace, GatherDirections::PerPixel)),
            },
            film: FilmState {
                width: 3,
                height: 2,
                samples: 9,
                half_samples: 4,
                sums: (0..n).map(|i| i as f32 * 0.5).collect(),
                half: (0..n).map(|i| i as f32 * 0.25).collect(),
            },
        }
    }

    #[test]
    fn a_checkpoint_reads_back_as_written() {
        let c = sample();
        assert_eq!(Checkpoint::from_bytes(Path::new("c"), &c.to_bytes()).unwrap(), c);
    }

    #[test]
    fn every_truncation_and_every_flipped_byte_is_refused() {
        let bytes = sample().to_bytes();
        for len in 0..bytes.len() {
            assert!(Checkpoint::from_bytes(Path::new("c"), &bytes[..len]).is_err(), "truncated to {len}");
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            assert!(Checkpoint::from_bytes(Path::new("c"), &b).is_err(), "byte {i} flipped");
        }
    }

    #[test]
    fn mismatches_are_named() {
        let c = sample();
        let mut other = c.settings.clone();
        other[1].1 = "200".into();
        let e = c.check_matches(Path::new("c"), c.scene_hash, &other, None).unwrap_err().to_string();
        assert!(e.contains("photons 100, here 200"), "{e}");
        let e = c.check_matches(Path::new("c"), 1, &c.settings, None).unwrap_err().to_string();
        assert!(e.contains("another scene"), "{e}");
        let e = c.check_matches(Path::new("c"), c.scene_hash, &c.settings, Some(8)).unwrap_err().to_string();
        assert!(e.contains("--seed 7"), "{e}");
        assert!(c.check_matches(Path::new("c"), c.scene_hash, &c.settings, Some(7)).is_ok());
    }
}
