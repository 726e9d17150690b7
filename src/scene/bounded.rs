//! Scene files read with a bound decided before reading (issue 27): at most
//! what the largest scene ballpit accepts can need, lines no longer than a
//! row can be, text only, and a source that stops sending for
//! [`IDLE`] is refused, so `/dev/zero`, `/dev/urandom`, a FIFO that never
//! closes or a huge sparse file ends in one message, in bounded time and
//! memory.
use crate::error::BadInput;
use crate::{bad, bad_input};
use rustix::event::{PollFd, PollFlags, Timespec};
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::time::Duration;

/// What a kind of scene file may hold.
#[derive(Clone, Copy, Debug)]
pub struct Bound {
    /// "CSV" or "TOML", for messages.
    pub kind: &'static str,
    pub max_bytes: u64,
    pub max_line: usize,
    pub max_lines: usize,
    /// Why `max_bytes` (what scene it allows).
    pub why: &'static str,
}

/// A pipe, FIFO or device that sends nothing for this long has not ended
/// and is refused: a scene file is read at disk speed.
pub const IDLE: Duration = Duration::from_secs(1);

/// The text of `path`, within `bound`, or one message saying what is wrong.
pub fn read_text(path: &Path, bound: &Bound) -> Result<String, BadInput> {
    let name = path.display();
    let cannot = |e: &dyn std::fmt::Display| bad_input!("cannot read scene file {name}: {e}");
    let meta = std::fs::metadata(path).map_err(|e| cannot(&e))?;
    if meta.is_dir() {
        return bad!("cannot read scene file {name}: it is a directory");
    }
    let max = bound.max_bytes;
    if meta.is_file() && meta.len() > max {
        return too_big(bound, &name, Some(meta.len()));
    }
    // Not blocking: a FIFO without a writer would hold `open` forever.
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NONBLOCK.bits().cast_signed())
        .open(path)
        .map_err(|e| cannot(&e))?;
    let idle = Timespec {
        tv_sec: IDLE.as_secs().cast_signed(),
        tv_nsec: 0,
    };
    let mut text = Vec::new();
    let mut buf = vec![0u8; 64 * 1024];
    let (mut line, mut line_len) = (1usize, 0usize);
    loop {
        let mut fds = [PollFd::new(&file, PollFlags::IN)];
        match rustix::event::poll(&mut fds, Some(&idle)) {
            Ok(0) => {
                return bad!(
                    "scene file {name} sent nothing for {} s without ending (a FIFO or device that never closes?)",
                    IDLE.as_secs()
                );
            }
            Ok(_) | Err(rustix::io::Errno::INTR) => {}
            Err(e) => return Err(cannot(&e)),
        }
        let n = match rustix::io::read(&file, &mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(rustix::io::Errno::AGAIN | rustix::io::Errno::INTR) => continue,
            Err(e) => return Err(cannot(&e)),
        };
        let chunk = &buf[..n];
        if text.len() as u64 + n as u64 > max {
            return too_big(bound, &name, None);
        }
        for &b in chunk {
            if b == b'\n' {
                line += 1;
                line_len = 0;
                if line > bound.max_lines {
                    return bad!(
                        "{name}: more than the {} lines a {} scene may have",
                        bound.max_lines,
                        bound.kind
                    );
                }
                continue;
            }
            line_len += 1;
            if line_len > bound.max_line {
                return bad!(
                    "{name} line {line}: longer than the {} bytes a {} scene line may have",
                    bound.max_line,
                    bound.kind
                );
            }
            // Text only: a scene never holds control characters (TOML
            // forbids them, CSV numbers have none).
            if (b < 0x20 && b != b'\t' && b != b'\r') || b == 0x7f {
                return bad!("{name} line {line}: byte 0x{b:02x} is not text");
            }
        }
        text.extend_from_slice(chunk);
    }
    super::utf8(text, &name.to_string())
}

/// The message for a file over the bound; `len` when known before reading.
fn too_big(
    bound: &Bound,
    name: &impl std::fmt::Display,
    len: Option<u64>,
) -> Result<String, BadInput> {
    let size = len.map_or_else(
        || format!("more than {} bytes", bound.max_bytes),
        |l| format!("{l} bytes"),
    );
    bad!(
        "scene file {name} is {size}; a {} scene is at most {} bytes ({})",
        bound.kind,
        bound.max_bytes,
        bound.why
    )
}
