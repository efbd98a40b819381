//! The gather's directions: the shared ones (an Owen-scrambled Sobol' sequence over the sphere, one
//! scramble per restart), the per-pixel ones' keys, and the sampler that draws them.

use glam::{Vec2, Vec3};

use super::estimator::GatherSample;
use crate::gpu::consts::MAX_DIRECTIONS;
use crate::passes::FixedSample;
use crate::sampling::{Rng, pcg_hash, sobol_owen_2d, stream, uniform_sphere, unit_f32};

/// The shared gather direction of index `i` for a restart whose scramble seed is `scramble`
/// ([`shared_scramble`]): the Owen-scrambled Sobol' point mapped uniformly to the sphere.
pub fn gather_direction(i: u32, scramble: u32) -> Vec3 {
    let [u1, u2] = sobol_owen_2d(i, scramble);
    uniform_sphere(unit_f32(u1), unit_f32(u2))
}

/// The scramble seed of the shared directions for the stream (seed, restart).
pub fn shared_scramble(seed: u32, restart: u32) -> u32 {
    pcg_hash(restart ^ pcg_hash(seed ^ stream::GATHER_SHARED))
}

/// The key of the per-pixel scramble seeds for the stream (seed, restart).
pub fn pixel_key(seed: u32, restart: u32) -> u32 {
    pcg_hash(restart ^ pcg_hash(seed ^ stream::GATHER_PIXEL))
}

/// The gather's random choices: the scramble of the shared directions and the key of the
/// per-pixel ones, drawn anew at every restart, and the ray view's sub-texel offsets, from the
/// streams keyed by the seed.
#[derive(Clone, Copy, Debug)]
pub struct DirectionSampler {
    seed: u32,
    /// Restarts so far (camera moves, resizes).
    restart: u32,
}

impl DirectionSampler {
    pub fn new(seed: u32) -> DirectionSampler {
        DirectionSampler { seed, restart: 0 }
    }

    /// The key of the per-pixel scramble seeds of this restart ([`PixelSamples::key`](super::PixelSamples::key)).
    pub fn pixel_key(&self) -> u32 {
        pixel_key(self.seed, self.restart)
    }

    /// A new image: new scrambles of the sequences.
    pub fn restart(&mut self) {
        self.restart += 1;
    }

    /// The `count` directions of `iteration` (one where `fixed` gives the direction), each
    /// with a uniform sub-texel offset in [-½, ½)².
    pub fn samples(&self, iteration: u32, count: u32, fixed: &FixedSample) -> Vec<GatherSample> {
        let k = if fixed.direction.is_some() { 1 } else { count.clamp(1, MAX_DIRECTIONS) };
        (0..k)
            .map(|j| {
                let index = iteration * k + j;
                let direction = fixed
                    .direction
                    .unwrap_or_else(|| gather_direction(index, shared_scramble(self.seed, self.restart)));
                let texel_jitter = fixed.texel_jitter.unwrap_or_else(|| {
                    let mut rng = Rng::new(self.seed ^ stream::TEXEL_JITTER, index, self.restart);
                    Vec2::new(rng.next_f32(), rng.next_f32()) - 0.5
                });
                GatherSample { direction: direction.normalize(), texel_jitter }
            })
            .collect()
    }
}
