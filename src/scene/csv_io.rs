//! Sphere CSV: header `x,y,z,vx,vy,vz,radius,mass`, one sphere a row.
//! Numbers are written in Rust's shortest round-trip form, so a dump reads
//! back bit for bit (ryu, which csv's serializer uses, writes 3.4e-5 as
//! 0.000034, hence the strings).
use super::MAX_COUNT;
use super::bounded::Bound;
use super::place::{Overlaps, check_with};
use crate::error::BadInput;
use crate::physics::{Sphere, World};
use crate::{bad, bad_input};
use glam::DVec3;
use std::io::Write;
use std::path::Path;

pub const HEADER: [&str; 8] = ["x", "y", "z", "vx", "vy", "vz", "radius", "mass"];

/// What a sphere CSV may hold, decided before reading: `MAX_COUNT` rows of
/// at most 256 bytes (a row of eight shortest round-trip numbers is at most
/// about 200).
pub const BOUND: Bound = Bound {
    kind: "CSV",
    max_bytes: MAX_COUNT as u64 * 256 + 1024,
    max_line: 1024,
    // The header, the rows and some blank lines.
    max_lines: MAX_COUNT + 1024,
    why: "10000000 spheres, 256 bytes a row",
};

pub fn read(path: &Path, size: f64, overlaps: Overlaps) -> Result<World, BadInput> {
    let name = path.display().to_string();
    let text = super::bounded::read_text(path, &BOUND)?;
    parse_with(text, size, &name, overlaps)
}

/// Parse CSV text; `name` prefixes every message (`file.csv line 7: ...`).
pub fn parse(text: &str, size: f64, name: &str) -> Result<World, BadInput> {
    parse_with(text.to_owned(), size, name, Overlaps::Refuse)
}

/// [`parse`], with overlapping spheres refused or allowed. The text goes
/// once its rows are read, before the spheres are checked: at a million
/// spheres it is 160 MB, and the check's grid came on top of it.
pub fn parse_with(
    text: String,
    size: f64,
    name: &str,
    overlaps: Overlaps,
) -> Result<World, BadInput> {
    if text.trim().is_empty() {
        return bad!(
            "{name}: the file is empty: a sphere CSV needs the header `{}` and a row a sphere",
            HEADER.join(",")
        );
    }
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    check_header(&mut rdr, name)?;
    let mut spheres = Vec::new();
    // Each record's line, for the check's messages, counted on from the
    // last record's (from the file's start each time, loading was
    // quadratic in the file's size).
    let mut lines = Vec::new();
    let mut at = Lines::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| line_at(&text, p.byte()));
            bad_input!("{name} line {line}: {e}")
        })?;
        let start = rec.position().map_or(0, csv::Position::byte);
        let line = at.line_of(&text, start);
        spheres.push(sphere_of(&rec, name, line)?);
        // At most MAX_COUNT rows and some blank lines: a u32 holds the line.
        lines.push(u32::try_from(line).unwrap_or(u32::MAX));
    }
    drop(rdr);
    drop(text);
    if spheres.is_empty() {
        return bad!(
            "{name}: a header and no spheres: give a row a sphere (for none, use --count 0)"
        );
    }
    let world = World::new(size, spheres);
    check_with(&world, overlaps, name, &|i| format!("line {}", lines[i]))?;
    Ok(world)
}

/// Lines counted through a text in order: the line of each record start
/// given, each no earlier than the last.
struct Lines {
    /// A byte of the text, and the (1-based) line it is on.
    byte: usize,
    line: usize,
}

impl Lines {
    fn new() -> Self {
        Lines { byte: 0, line: 1 }
    }

    /// The line of the record at `start`, as [`line_at`] counts it.
    fn line_of(&mut self, text: &str, start: u64) -> usize {
        let to = first_in_line(text, start).max(self.byte);
        // memchr's search, not a byte loop: one pass over 160 MB at 1M.
        self.line += memchr::memchr_iter(b'\n', &text.as_bytes()[self.byte..to]).count();
        self.byte = to;
        self.line
    }
}

/// The first row is [`HEADER`], or the message says what it is instead.
fn check_header(rdr: &mut csv::Reader<&[u8]>, name: &str) -> Result<(), BadInput> {
    let header = rdr
        .headers()
        .map_err(|e| bad_input!("{name} line 1: cannot read the header: {e}"))?;
    if header.iter().collect::<Vec<_>>() != HEADER {
        return bad!(
            "{name} line 1: header must be `{}`, got `{}`",
            HEADER.join(","),
            header.iter().collect::<Vec<_>>().join(",")
        );
    }
    Ok(())
}

/// The line of `text` a record at `byte` is on. Lines are counted from the
/// bytes, not by the reader, so CRLF files count like LF ones (a record's
/// position may be the `\n` ending the last).
fn line_at(text: &str, byte: u64) -> usize {
    super::line_of(text, first_in_line(text, byte))
}

/// The first byte at or after `byte` that ends no line.
fn first_in_line(text: &str, byte: u64) -> usize {
    let start = (byte as usize).min(text.len());
    let skip = text.as_bytes()[start..]
        .iter()
        .take_while(|&&b| b == b'\r' || b == b'\n')
        .count();
    start + skip
}

/// The sphere of one row, or what is wrong with it at `line`.
fn sphere_of(rec: &csv::StringRecord, name: &str, line: usize) -> Result<Sphere, BadInput> {
    if rec.len() != 8 {
        return bad!(
            "{name} line {}: expected 8 fields, found {}",
            line,
            rec.len()
        );
    }
    let mut v = [0.0; 8];
    for (k, (slot, field)) in v.iter_mut().zip(rec.iter()).enumerate() {
        *slot = field.parse().map_err(|_| {
            bad_input!(
                "{name} line {}: {} = `{field}` is not a number",
                line,
                HEADER[k]
            )
        })?;
    }
    Ok(Sphere {
        pos: DVec3::new(v[0], v[1], v[2]),
        vel: DVec3::new(v[3], v[4], v[5]),
        radius: v[6],
        mass: v[7],
    })
}

pub fn write(world: &World, out: &mut impl Write) -> csv::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(HEADER)?;
    for s in &world.spheres {
        let (p, v) = (s.pos, s.vel);
        let fields = [p.x, p.y, p.z, v.x, v.y, v.z, s.radius, s.mass].map(|x| format!("{x:?}"));
        w.write_record(&fields)?;
    }
    w.flush()?;
    Ok(())
}

/// Opens `path` for a dump, before the run that makes the world: a path
/// that cannot be written fails at once, not after a long run.
pub fn create(path: &Path) -> Result<DumpFile, BadInput> {
    let file = std::fs::File::create(path)
        .map_err(|e| bad_input!("cannot write {}: {e}", path.display()))?;
    Ok(DumpFile {
        file,
        path: path.to_owned(),
    })
}

/// A sphere CSV opened by [`create`], written by [`DumpFile::write`].
pub struct DumpFile {
    file: std::fs::File,
    path: std::path::PathBuf,
}

impl DumpFile {
    pub fn write(self, world: &World) -> Result<(), BadInput> {
        let mut w = std::io::BufWriter::new(self.file);
        write(world, &mut w)
            .and_then(|()| w.flush().map_err(csv::Error::from))
            .map_err(|e| bad_input!("cannot write {}: {e}", self.path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::{Lines, line_at, parse};
    use std::fmt::Write;

    /// Counted on from record to record, a record's line is the one
    /// counted from the start: blank lines, CRLF and LF mixed.
    #[test]
    fn lines_counted_in_order_are_lines_counted_from_the_start() {
        let mut text = String::from("x,y,z,vx,vy,vz,radius,mass\r\n");
        for k in 0..200 {
            let end = ["\n", "\r\n", "\n\n", "\r\n\r\n\r\n", "\n \n"][k % 5];
            write!(text, "0.{k:03},0.5,0.5,0,0,0,0.0001,1{end}").unwrap();
        }
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::All)
            .flexible(true)
            .from_reader(text.as_bytes());
        let mut at = Lines::new();
        let mut records = 0;
        for rec in rdr.records() {
            let start = rec.unwrap().position().unwrap().byte();
            assert_eq!(
                at.line_of(&text, start),
                line_at(&text, start),
                "byte {start}"
            );
            records += 1;
        }
        assert!(records >= 200, "{records}");
    }

    /// The overlap check, run once the text is gone, names the lines.
    #[test]
    fn an_overlap_far_down_a_file_names_its_lines() {
        let mut text = String::from("x,y,z,vx,vy,vz,radius,mass\r\n\r\n");
        for k in 0..50 {
            write!(text, "0.{:02},0.1,0.1,0,0,0,0.001,1\r\n\n", k + 10).unwrap();
        }
        text += "0.9,0.9,0.9,0,0,0,0.01,1\n0.905,0.9,0.9,0,0,0,0.01,1\n";
        let err = parse(&text, 1.0, "o.csv").unwrap_err();
        // The header, a blank line, 50 rows with a blank line each.
        assert!(
            err.0.starts_with("o.csv: line 103 and line 104 overlap"),
            "{err}"
        );
    }
}
