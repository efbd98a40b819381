//! `rastergi noise`: the noise of one render, from renders of the same settings with
//! independent seeds ([`rastergi::metrics::seed_noise`]): no reference needed, and the share of
//! it in the worst pixels.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use rastergi::metrics::seed_noise;

use crate::compare::{DEFAULT_EMITTER_THRESHOLD, read};

#[derive(Args, Debug)]
pub struct NoiseArgs {
    /// Two or more renders of one scene with the same settings and different seeds (.exr, or
    /// .png decoded to linear).
    #[arg(required = true, num_args = 1..)]
    images: Vec<PathBuf>,
    /// Leave emitters out: pixels above THRESHOLD in any channel of the renders' mean (default
    /// 3), and their 8 neighbours. Give it after the file names or with a value.
    #[arg(long, value_name = "THRESHOLD", num_args = 0..=1, default_missing_value = DEFAULT_EMITTER_THRESHOLD)]
    mask_emitters: Option<f32>,
}

pub fn run(args: &NoiseArgs) -> Result<()> {
    let images = args.images.iter().map(|p| read(p)).collect::<Result<Vec<_>>>()?;
    let names: Vec<String> = args.images.iter().map(|p| p.display().to_string()).collect();
    let s = seed_noise(&images, &names, args.mask_emitters)?;
    let (w, h) = (images[0].width, images[0].height);
    println!("renders:          {} of {w} x {h}", s.renders);
    let masked = args.mask_emitters.map_or(String::new(), |t| {
        format!(" (emitter mask: the renders' mean above {t} in a channel, and neighbours)")
    });
    println!("compared pixels:  {} of {}{masked}", s.compared_pixels, s.total_pixels);
    println!("mean:             {:.6}", s.mean);
    println!(
        "noise:            {:.6}  (one render's relative RMSE against its expectation: sqrt(mean per-pixel variance over the renders) / mean)",
        s.relative
    );
    println!(
        "noise of mean:    {:.6}  (of the mean of the {} renders)",
        s.relative / (s.renders as f64).sqrt(),
        s.renders
    );
    println!("body:             {:.6}  (the noise over the best 99 % of the pixels)", s.body);
    println!("worst 1 %:        {:.4}  (their share of the squared noise)", s.tail_share);
    if !s.pairs.is_empty() {
        let pairs: Vec<String> = s.pairs.iter().map(|p| format!("{p:.6}")).collect();
        println!(
            "pairs:            {}  (the noise from each pair of renders alone, (1, 2), (3, 4) …: how much two tell)",
            pairs.join(" ")
        );
    }
    Ok(())
}
