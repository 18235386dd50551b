//! Depth and hit buffers of a render (where each pixel's camera rays first reached a surface)
//! and the `.aux` sidecar file that `sdfc render --aux` writes beside the PNG.
//!
//! The sidecar is little-endian binary:
//!
//! | offset | size | content |
//! |--------|------|---------|
//! | 0 | 8 | the magic bytes `SDFCAUX1` |
//! | 8 | 4 | width `W` (u32) |
//! | 12 | 4 | height `H` (u32) |
//! | 16 | 4 | camera rays per pixel `n` (u32, `aa²`) |
//! | 20 | 4·W·H | distance: per pixel, row-major from the top-left, the mean distance from the eye to the first hit of the pixel's camera rays that hit (f32; NaN where none hit) |
//! | 20 + 4·W·H | 4·W·H | coverage: per pixel, the fraction of its camera rays that hit (f32 in [0, 1]) |
//!
//! A pixel is a *hit* when at least half of its camera rays hit (with one ray per pixel: when
//! it hit). Distances are along the unit camera ray, in scene units.

use std::path::{Path, PathBuf};

/// The magic bytes that open a sidecar file.
pub const MAGIC: &[u8; 8] = b"SDFCAUX1";

/// The extension of the sidecar file (`OUT.png` → `OUT.aux`).
pub const EXTENSION: &str = "aux";

/// Per-pixel first hits of the camera rays.
#[derive(Debug, Clone, PartialEq)]
pub struct Depth {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Camera rays per pixel.
    pub samples: u32,
    /// Mean first-hit distance of the rays that hit; NaN where none hit.
    pub distance: Vec<f32>,
    /// Fraction of the pixel's camera rays that hit.
    pub coverage: Vec<f32>,
}

/// Why a sidecar file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum DepthError {
    /// The bytes are not a sidecar file of this format.
    #[error("not an sdfc depth sidecar: {0}")]
    Format(String),
    /// Reading or writing the file failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

impl Depth {
    /// A buffer where no pixel hit.
    pub fn empty(width: u32, height: u32, samples: u32) -> Self {
        let n = width as usize * height as usize;
        Depth {
            width,
            height,
            samples,
            distance: vec![f32::NAN; n],
            coverage: vec![0.0; n],
        }
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.coverage.len()
    }

    /// True for an image with no pixels.
    pub fn is_empty(&self) -> bool {
        self.coverage.is_empty()
    }

    /// Whether pixel `i` (row-major) is a hit: at least half of its camera rays hit.
    pub fn hit(&self, i: usize) -> bool {
        self.coverage[i] >= 0.5
    }

    /// The sidecar bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(20 + 8 * self.len());
        out.extend_from_slice(MAGIC);
        for v in [self.width, self.height, self.samples] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in self.distance.iter().chain(&self.coverage) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// Reads sidecar bytes, checking the magic and the length.
    pub fn decode(bytes: &[u8]) -> Result<Depth, DepthError> {
        if bytes.len() < 20 || &bytes[..8] != MAGIC {
            return Err(DepthError::Format("missing the SDFCAUX1 header".into()));
        }
        let word = |at: usize| {
            u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        let (width, height, samples) = (word(8), word(12), word(16));
        let n = width as usize * height as usize;
        if bytes.len() != 20 + 8 * n {
            return Err(DepthError::Format(format!(
                "{} bytes for a {width}x{height} image (expected {})",
                bytes.len(),
                20 + 8 * n
            )));
        }
        let floats = |from: usize| -> Vec<f32> {
            bytes[from..from + 4 * n]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect()
        };
        Ok(Depth {
            width,
            height,
            samples,
            distance: floats(20),
            coverage: floats(20 + 4 * n),
        })
    }

    /// Writes the sidecar file atomically.
    pub fn write(&self, path: &Path) -> Result<(), DepthError> {
        crate::image::write_atomic(path, &self.encode())?;
        Ok(())
    }

    /// Reads a sidecar file.
    pub fn read(path: &Path) -> Result<Depth, DepthError> {
        Depth::decode(&std::fs::read(path)?)
    }
}

/// The sidecar path of an image: `OUT.png` → `OUT.aux`.
pub fn sidecar_path(image: &Path) -> PathBuf {
    image.with_extension(EXTENSION)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_bad_input() {
        let d = Depth {
            width: 2,
            height: 1,
            samples: 4,
            distance: vec![1.5, f32::NAN],
            coverage: vec![1.0, 0.25],
        };
        let bytes = d.encode();
        assert_eq!(bytes.len(), 20 + 16);
        let back = Depth::decode(&bytes).expect("decodes");
        assert_eq!(back.distance[0], 1.5);
        assert!(back.distance[1].is_nan());
        assert_eq!(back.coverage, d.coverage);
        assert!(back.hit(0) && !back.hit(1));
        assert!(Depth::decode(&bytes[..30]).is_err());
        assert!(Depth::decode(b"PNG.....").is_err());
    }
}
