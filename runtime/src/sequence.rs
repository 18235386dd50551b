//! Frame sequences (docs/animation.md): the frame range `A..B`, the shard `I/N` of a job
//! array, the numbered file names of a pattern such as `out/frame_####.png`, and where a
//! sequence goes (numbered images, an animated PNG, or a video through `ffmpeg`).

use crate::output::Format;
use std::path::{Path, PathBuf};

/// A frame range, shard or sequence output that cannot be used: a usage error.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Error {
    /// `--frames` not as `A..B`.
    #[error("--frames expects A..B, the frames A up to B − 1, like 0..120, not `{0}`")]
    Frames(String),
    /// `--frames A..B` with no frame in it.
    #[error("--frames {0} has no frames: B must be greater than A (the range is half-open)")]
    NoFrames(String),
    /// `--shard` not as `I/N`.
    #[error("--shard expects I/N, shard I (from 0) of N, like 3/10, not `{0}`")]
    Shard(String),
    /// `--shard I/N` with I not below N.
    #[error("--shard {0}: the shard must be from 0 to N − 1 of N ≥ 1 shards (a job array's task ids from 0, as SLURM_ARRAY_TASK_ID with --array=0-{{N-1}} or JOB_COMPLETION_INDEX)")]
    NoShard(String),
    /// A run of `#` in a directory of the output's path.
    #[error("`{}`: the `#` run of the frame number must be in the file name, not in a directory", .0.display())]
    RunInDirectory(PathBuf),
    /// More than one run of `#`.
    #[error("`{}` has more than one run of `#`: one run is the frame number", .0.display())]
    Runs(PathBuf),
    /// Numbered frames in a format that is not an image's.
    #[error("cannot write `{}`: numbered frames are written as {}", .0.display(), crate::output::EXTENSIONS)]
    FrameFormat(PathBuf),
    /// An output that names no way to write a sequence.
    #[error("cannot write a sequence to `{}`: name numbered frames with a run of `#` (`out/frame_####.png`), or write an animated `.png`, or a video ({}, through ffmpeg)", .0.display(), video_extensions())]
    Target(PathBuf),
    /// A video asked for without `ffmpeg`.
    #[error("writing a video needs `ffmpeg` on PATH, and there is none; install it, or write numbered frames (`-o out/frame_####.png`) and encode them yourself")]
    NoFfmpeg,
}

/// The video extensions, as the messages list them.
fn video_extensions() -> String {
    VIDEO_EXTENSIONS
        .iter()
        .map(|e| format!("`.{e}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Frames `start..end` (half-open, as the language's `for` loops).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frames {
    /// The first frame.
    pub start: u64,
    /// One past the last frame.
    pub end: u64,
}

/// The two whole numbers of `s`, written either side of `between`.
fn two_numbers(s: &str, between: &str) -> Option<(u64, u64)> {
    let (a, b) = s.split_once(between)?;
    Some((a.trim().parse().ok()?, b.trim().parse().ok()?))
}

impl Frames {
    /// Parses `A..B` (frames A up to B − 1).
    pub fn parse(s: &str) -> Result<Frames, Error> {
        let (start, end) = two_numbers(s, "..").ok_or_else(|| Error::Frames(s.into()))?;
        if end <= start {
            return Err(Error::NoFrames(s.into()));
        }
        Ok(Frames { start, end })
    }

    /// The number of frames.
    pub fn len(&self) -> u64 {
        self.end - self.start
    }

    /// True for an empty range.
    pub fn is_empty(&self) -> bool {
        self.end <= self.start
    }
}

/// Shard `index` of `count`: the frames whose number is ≡ `index` (mod `count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, from 0.
    pub index: u64,
    /// How many shards there are.
    pub count: u64,
}

impl Default for Shard {
    fn default() -> Self {
        Shard { index: 0, count: 1 }
    }
}

impl Shard {
    /// Parses `I/N` with 0 ≤ I < N.
    pub fn parse(s: &str) -> Result<Shard, Error> {
        let (index, count) = two_numbers(s, "/").ok_or_else(|| Error::Shard(s.into()))?;
        if count == 0 || index >= count {
            return Err(Error::NoShard(s.into()));
        }
        Ok(Shard { index, count })
    }

    /// The frames of `frames` in this shard, in order.
    pub fn frames(&self, frames: Frames) -> impl Iterator<Item = u64> {
        let Shard { index, count } = *self;
        (frames.start..frames.end).filter(move |k| k % count == index)
    }
}

/// A file name with one run of `#`, replaced by the zero-padded frame number (wider numbers
/// are written in full): `out/frame_####.png` names frame 7 `out/frame_0007.png`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pattern {
    before: String,
    width: usize,
    after: String,
}

impl Pattern {
    /// The pattern of `path`, or `None` when its file name has no `#`. A second run of `#`
    /// is an error.
    pub fn new(path: &Path) -> Result<Option<Pattern>, Error> {
        let text = path.to_string_lossy();
        let name_start = text.len() - path.file_name().map_or(0, |n| n.to_string_lossy().len());
        let Some(first) = text[name_start..].find('#').map(|i| i + name_start) else {
            if text.contains('#') {
                return Err(Error::RunInDirectory(path.to_path_buf()));
            }
            return Ok(None);
        };
        let width = text[first..].chars().take_while(|&c| c == '#').count();
        let after = &text[first + width..];
        if after.contains('#') || text[..first].contains('#') {
            return Err(Error::Runs(path.to_path_buf()));
        }
        Ok(Some(Pattern {
            before: text[..first].to_string(),
            width,
            after: after.to_string(),
        }))
    }

    /// The file of frame `k`.
    pub fn path(&self, k: u64) -> PathBuf {
        PathBuf::from(format!(
            "{}{:0width$}{}",
            self.before,
            k,
            self.after,
            width = self.width
        ))
    }
}

/// Where a sequence goes, decided by `-o`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// One image per frame, named by the pattern, in the format of its extension.
    Numbered(Pattern, Format),
    /// One animated PNG (APNG) of every frame.
    Apng(PathBuf),
    /// A video encoded by `ffmpeg`, in the container its extension names.
    Video(PathBuf),
}

/// The extensions written through `ffmpeg`.
pub const VIDEO_EXTENSIONS: &[&str] = &["mp4", "webm", "mkv", "mov", "gif"];

impl Target {
    /// The target `-o PATH` names for a sequence.
    pub fn new(path: &Path) -> Result<Target, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if let Some(pattern) = Pattern::new(path)? {
            let format = Format::from_extension(&ext)
                .ok_or_else(|| Error::FrameFormat(path.to_path_buf()))?;
            return Ok(Target::Numbered(pattern, format));
        }
        if ext == "png" {
            return Ok(Target::Apng(path.to_path_buf()));
        }
        if VIDEO_EXTENSIONS.contains(&ext.as_str()) {
            return Ok(Target::Video(path.to_path_buf()));
        }
        Err(Error::Target(path.to_path_buf()))
    }
}

/// The `ffmpeg` on `PATH`, or why there is none.
pub fn ffmpeg() -> Result<PathBuf, Error> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|d| d.join("ffmpeg"))
        .find(|p| p.is_file())
        .ok_or(Error::NoFfmpeg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_frames() {
        let frames = Frames { start: 3, end: 50 };
        for n in 1..8 {
            let mut seen = vec![0; 50];
            for i in 0..n {
                for k in (Shard { index: i, count: n }).frames(frames) {
                    seen[k as usize] += 1;
                }
            }
            assert!(seen[..3].iter().all(|&c| c == 0));
            assert!(seen[3..].iter().all(|&c| c == 1), "{n} shards: {seen:?}");
        }
    }

    #[test]
    fn patterns_number_frames() {
        let p = Pattern::new(Path::new("out/frame_####.png"))
            .unwrap()
            .unwrap();
        assert_eq!(p.path(7), PathBuf::from("out/frame_0007.png"));
        assert_eq!(p.path(123456), PathBuf::from("out/frame_123456.png"));
        let p = Pattern::new(Path::new("f#.exr")).unwrap().unwrap();
        assert_eq!(p.path(12), PathBuf::from("f12.exr"));
        assert_eq!(Pattern::new(Path::new("still.png")).unwrap(), None);
        assert_eq!(
            Pattern::new(Path::new("a##_##.png"))
                .unwrap_err()
                .to_string(),
            "`a##_##.png` has more than one run of `#`: one run is the frame number"
        );
        assert_eq!(
            Pattern::new(Path::new("dir#/f.png")).unwrap_err().to_string(),
            "`dir#/f.png`: the `#` run of the frame number must be in the file name, not in a directory"
        );
    }

    #[test]
    fn ranges_and_shards_parse() {
        assert_eq!(
            Frames::parse("0..120").unwrap(),
            Frames { start: 0, end: 120 }
        );
        assert_eq!(
            Frames::parse("5..5").unwrap_err().to_string(),
            "--frames 5..5 has no frames: B must be greater than A (the range is half-open)"
        );
        assert_eq!(
            Frames::parse("5").unwrap_err().to_string(),
            "--frames expects A..B, the frames A up to B − 1, like 0..120, not `5`"
        );
        assert_eq!(
            Shard::parse("3/10").unwrap(),
            Shard {
                index: 3,
                count: 10
            }
        );
        assert_eq!(
            Shard::parse("10/10").unwrap_err().to_string(),
            "--shard 10/10: the shard must be from 0 to N − 1 of N ≥ 1 shards (a job array's task ids from 0, as SLURM_ARRAY_TASK_ID with --array=0-{N-1} or JOB_COMPLETION_INDEX)"
        );
        assert_eq!(
            Shard::parse("0/0").unwrap_err(),
            Error::NoShard("0/0".into())
        );
        assert_eq!(Shard::parse("3").unwrap_err(), Error::Shard("3".into()));
    }

    #[test]
    fn sequence_outputs_name_what_they_can_be() {
        assert_eq!(
            Target::new(Path::new("out.txt")).unwrap_err().to_string(),
            "cannot write a sequence to `out.txt`: name numbered frames with a run of `#` (`out/frame_####.png`), or write an animated `.png`, or a video (`.mp4`, `.webm`, `.mkv`, `.mov`, `.gif`, through ffmpeg)"
        );
        let refused = Target::new(Path::new("f_##.txt")).unwrap_err().to_string();
        assert!(
            refused.starts_with("cannot write `f_##.txt`: numbered frames are written as "),
            "{refused}"
        );
    }
}
