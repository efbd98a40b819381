//! Screenshots of the viewer (the P key and the script's `screenshot`): the image as shown
//! (PNG) and its linear radiance (EXR), under names `rastergi-NNNN` that never overwrite a
//! file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use rastergi::image_io::{write_exr, write_png};
use rastergi::passes::denoise::DenoiseParams;
use rastergi::passes::film::Show;
use rastergi::progressive::Progressive;

/// Screenshot names `rastergi-NNNN.png` / `.exr` in a directory, counting up.
pub struct Screenshots {
    dir: PathBuf,
    next: u32,
}

impl Screenshots {
    /// Screenshots into `dir` (empty: the current directory, names printed relative to it),
    /// numbered from 1.
    pub fn new(dir: PathBuf) -> Screenshots {
        Screenshots { dir, next: 1 }
    }

    /// Reserves the first `rastergi-NNNN` at or after the counter for which neither the PNG
    /// nor the EXR exists, by creating both empty (`create_new`): existing files are never
    /// overwritten, and another viewer saving into the same directory cannot take the name.
    fn reserve(&mut self) -> Result<(PathBuf, PathBuf)> {
        for n in self.next..=9999 {
            let png = self.dir.join(format!("rastergi-{n:04}.png"));
            let exr = self.dir.join(format!("rastergi-{n:04}.exr"));
            let create = |p: &Path| std::fs::OpenOptions::new().write(true).create_new(true).open(p);
            match create(&png) {
                Ok(_) => {}
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e).with_context(|| format!("{}: cannot create the screenshot", png.display())),
            }
            match create(&exr) {
                Ok(_) => {}
                Err(e) => {
                    let _ = std::fs::remove_file(&png);
                    if e.kind() == std::io::ErrorKind::AlreadyExists {
                        continue;
                    }
                    return Err(e).with_context(|| format!("{}: cannot create the screenshot", exr.display()));
                }
            }
            self.next = n + 1;
            return Ok((png, exr));
        }
        bail!("{}: rastergi-0000 to rastergi-9999 are all taken; choose another --screenshot-dir", self.dir.display())
    }

    /// Saves the image as shown (PNG) and its linear radiance (EXR): `denoised` (the full
    /// image, filtered at the iterations it holds now, where the renderer has a denoiser
    /// enabled) or the raw image of `show`; returns the two paths.
    pub fn save(
        &mut self,
        renderer: &dyn Progressive,
        show: Show,
        exposure: f32,
        denoised: bool,
    ) -> Result<(PathBuf, PathBuf)> {
        let (display, linear) = match renderer.denoising().filter(|_| denoised) {
            Some(r) => {
                let params = DenoiseParams::default();
                (r.read_display_denoised(&params, exposure)?, r.read_denoised(&params)?)
            }
            None => (renderer.read_display(show, exposure)?, renderer.read_linear(show)?),
        };
        let (png, exr) = self.reserve()?;
        let written = write_png(&png, &display).and_then(|()| write_exr(&exr, &linear));
        if let Err(e) = written {
            let _ = std::fs::remove_file(&png);
            let _ = std::fs::remove_file(&exr);
            return Err(e.into());
        }
        Ok((png, exr))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screenshots_never_overwrite_and_count_on() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("rastergi-0001.png"), b"keep").unwrap();
        std::fs::write(dir.path().join("rastergi-0002.exr"), b"keep").unwrap();
        let mut s = Screenshots::new(dir.path().to_path_buf());
        let (png, exr) = s.reserve().unwrap();
        assert_eq!(
            (png.file_name().unwrap(), exr.file_name().unwrap()),
            ("rastergi-0003.png".as_ref(), "rastergi-0003.exr".as_ref())
        );
        assert_eq!(std::fs::read(dir.path().join("rastergi-0001.png")).unwrap(), b"keep");
        assert!(!dir.path().join("rastergi-0002.png").exists(), "a half-taken pair is left alone");
        assert_eq!(s.reserve().unwrap().0.file_name().unwrap(), "rastergi-0004.png");
    }
}
