//! `frames.csv`: one row per frame.

use super::{FrameRecord, Phase, ProfileError, write_file};
use std::io::{self, Write};
use std::path::Path;

/// Header of `frames.csv`; the suffix of each column is its unit. `warmup` is 1 or 0,
/// `gpu_ms` is empty when the GPU time is unknown.
pub const CSV_HEADER: &str = "frame,start_s,warmup,frame_ms,input_ms,delta_ms,upload_ms,\
record_ms,submit_ms,present_ms,gpu_ms,bytes_uploaded,samples_touched";

pub fn write_frames_csv(path: &Path, frames: &[FrameRecord]) -> Result<(), ProfileError> {
    write_file(path, |w| write_frames_csv_to(w, frames))
}

/// Writes the CSV to any writer (stdout, a buffer in tests).
pub fn write_frames_csv_to(w: &mut impl Write, frames: &[FrameRecord]) -> io::Result<()> {
    writeln!(w, "{CSV_HEADER}")?;
    for f in frames {
        // Microsecond start times and 0.1 µs phase times: finer than `Instant` is worth on
        // most systems, coarse enough to keep the file small.
        write!(
            w,
            "{},{:.6},{},{:.4}",
            f.index,
            f.start_s,
            u8::from(f.warmup),
            f.frame_ms
        )?;
        for phase in Phase::ALL {
            write!(w, ",{:.4}", f.phase_ms[phase])?;
        }
        match f.gpu_ms {
            Some(gpu) => write!(w, ",{gpu:.4}")?,
            None => write!(w, ",")?,
        }
        writeln!(w, ",{},{}", f.bytes_uploaded, f.samples_touched)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_matches_phase_order() {
        let names: Vec<String> = Phase::ALL.iter().map(|p| format!("{p}_ms")).collect();
        assert!(CSV_HEADER.contains(&names.join(",")));
    }

    #[test]
    fn row_layout() {
        let mut f = FrameRecord {
            index: 3,
            start_s: 0.5,
            warmup: true,
            frame_ms: 16.0,
            bytes_uploaded: 64,
            samples_touched: 9,
            ..FrameRecord::default()
        };
        f.phase_ms[Phase::Delta] = 1.25;
        let mut out = Vec::new();
        write_frames_csv_to(&mut out, &[f.clone()]).unwrap();
        f.gpu_ms = Some(2.0);
        f.warmup = false;
        write_frames_csv_to(&mut out, &[f]).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[1],
            "3,0.500000,1,16.0000,0.0000,1.2500,0.0000,0.0000,0.0000,0.0000,,64,9"
        );
        assert_eq!(
            lines[3],
            "3,0.500000,0,16.0000,0.0000,1.2500,0.0000,0.0000,0.0000,0.0000,2.0000,64,9"
        );
    }
}
