//! `frames.csv`: one row per frame.

use super::{FrameRecord, Phase, ProfileError, write_file};
use std::io::{self, Write};
use std::path::Path;

/// Header of `frames.csv`; the suffix of each column is its unit. `warmup` is 1 or 0,
/// `gpu_ms` is empty when the GPU time is unknown.
pub const CSV_HEADER: &str = "frame,start_s,warmup,frame_ms,input_ms,delta_ms,upload_ms,\
record_ms,submit_ms,present_ms,gpu_ms,bytes_uploaded,samples_touched,retained,layer_built,\
triangles";

pub fn write_frames_csv(path: &Path, frames: &[FrameRecord]) -> Result<(), ProfileError> {
    write_file(path, |w| write_frames_csv_to(w, frames))
}

/// Writes the CSV to any writer (stdout, a buffer in tests).
///
/// Through the `csv` crate: it quotes any field that needs it and refuses a row whose length
/// differs from the header's, so a column added to one side only fails loudly instead of
/// shifting every later column.
pub fn write_frames_csv_to(w: &mut impl Write, frames: &[FrameRecord]) -> io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    out.write_record(CSV_HEADER.split(','))?;
    for f in frames {
        out.write_record(row(f))?;
    }
    out.flush()
}

/// The cells of one frame, in [`CSV_HEADER`] order.
fn row(f: &FrameRecord) -> Vec<String> {
    // Microsecond start times and 0.1 µs phase times: finer than `Instant` is worth on most
    // systems, coarse enough to keep the file small.
    let mut cells = vec![
        f.index.to_string(),
        format!("{:.6}", f.start_s),
        u8::from(f.warmup).to_string(),
        format!("{:.4}", f.frame_ms),
    ];
    cells.extend(Phase::ALL.map(|phase| format!("{:.4}", f.phase_ms[phase])));
    cells.push(f.gpu_ms.map_or_else(String::new, |gpu| format!("{gpu:.4}")));
    cells.push(f.bytes_uploaded.to_string());
    cells.push(f.samples_touched.to_string());
    cells.push(u8::from(f.retained).to_string());
    cells.push(u8::from(f.layer_built).to_string());
    cells.push(f.triangles.to_string());
    cells
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
        (f.retained, f.layer_built, f.triangles) = (true, true, 1200);
        write_frames_csv_to(&mut out, &[f]).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[1],
            "3,0.500000,1,16.0000,0.0000,1.2500,0.0000,0.0000,0.0000,0.0000,,64,9,0,0,0"
        );
        assert_eq!(
            lines[3],
            "3,0.500000,0,16.0000,0.0000,1.2500,0.0000,0.0000,0.0000,0.0000,2.0000,64,9,1,1,1200"
        );
    }
}
