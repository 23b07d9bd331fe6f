//! The stable-toolchain mutation fuzzer: seeds, mutations, and the loop that runs one target.
//!
//! Shared by the CI test (`tests/fuzz_stable.rs`, a bounded number of executions per target) and
//! the long run (`examples/fuzz_stable.rs`, driven by `bench/fuzz.sh`), so both mutate the same
//! way. Every execution's input is a function of the run's seed, the target's name and the
//! execution's index alone ([`Runner::input`]): a finding can be rebuilt from those three
//! numbers. Targets run in-process; a panic is caught with `catch_unwind`, an execution is timed
//! (over [`Limits::slow`] it is reported as slow, over [`Limits::hang`] it is a finding), and a
//! watchdog thread saves the input and stops the process when one execution never returns.

use std::cell::{Cell, RefCell};
use std::io::{Cursor, Read, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, Once};
use std::time::{Duration, Instant};

/// A tiny deterministic PRNG (splitmix64): the same seed gives the same mutations everywhere.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator starting from `seed`.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }

    /// True once in `n` calls on average.
    pub fn one_in(&mut self, n: usize) -> bool {
        self.below(n) == 0
    }

    /// A length in `1..=max`, small lengths more likely (half the time at most 8).
    pub fn size(&mut self, max: usize) -> usize {
        let max = max.max(1);
        if self.one_in(2) {
            1 + self.below(max.min(8))
        } else {
            1 + self.below(max)
        }
    }

    /// One element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// FNV-1a of `bytes`: names a target in the per-execution seed and a finding's file.
pub fn fnv(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// One seed file (or a built-in one): its extension, lower case, and its bytes; a zip package
/// also keeps its entries, so that the XML inside can be mutated and zipped again.
#[derive(Debug, Clone)]
pub struct Seed {
    /// Where it came from, for messages.
    pub name: String,
    /// Extension, lower case, without the dot (empty when the name has none).
    pub ext: String,
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// The entries of a zip package (name, uncompressed bytes), when the seed is one.
    pub entries: Option<Vec<(String, Vec<u8>)>>,
}

impl Seed {
    /// A seed of `bytes` named `name`, its zip entries read when it is a small enough package.
    pub fn new(name: &str, bytes: Vec<u8>) -> Self {
        let ext = Path::new(name)
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let entries = if bytes.starts_with(b"PK\x03\x04") {
            unzip(&bytes, bytes.len().saturating_mul(8).max(1 << 20))
        } else {
            None
        };
        Seed {
            name: name.to_owned(),
            ext,
            bytes,
            entries,
        }
    }
}

/// The entries of a zip of at most 64 entries whose uncompressed total stays under `budget`.
fn unzip(bytes: &[u8], budget: usize) -> Option<Vec<(String, Vec<u8>)>> {
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).ok()?;
    if zip.len() > 64 {
        return None;
    }
    let mut out = Vec::new();
    let mut total = 0usize;
    for i in 0..zip.len() {
        let mut f = zip.by_index(i).ok()?;
        if f.is_dir() {
            continue;
        }
        let name = f.name().ok()?.into_owned();
        let mut data = Vec::new();
        f.by_ref()
            .take((budget - total) as u64 + 1)
            .read_to_end(&mut data)
            .ok()?;
        total += data.len();
        if total > budget {
            return None;
        }
        out.push((name, data));
    }
    Some(out)
}

/// Files under `dirs` (recursively, sorted by path) of at most `max_bytes` each, as seeds.
/// Folders that do not exist are skipped.
pub fn collect_seeds(dirs: &[PathBuf], max_bytes: u64) -> Vec<Seed> {
    let mut files = Vec::new();
    for dir in dirs {
        walk(dir, &mut files);
    }
    files.sort();
    files
        .iter()
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() <= max_bytes && m.len() > 0))
        .filter_map(|p| {
            let bytes = std::fs::read(p).ok()?;
            Some(Seed::new(&p.to_string_lossy(), bytes))
        })
        .collect()
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        match e.file_type() {
            Ok(t) if t.is_dir() => walk(&p, out),
            Ok(t) if t.is_file() => out.push(p),
            _ => {}
        }
    }
}

/// The seed folders of a checkout at `root`: the fuzzer's own seeds, the samples, and the
/// shared corpus and regression files beside the checkout when they are there. Returns the
/// folders and one line per folder that is absent.
pub fn seed_dirs(root: &Path) -> (Vec<PathBuf>, Vec<String>) {
    let mut dirs = vec![root.join("tests/fuzz_stable/seeds"), root.join("samples")];
    let mut notes = Vec::new();
    for shared in ["../shared/corpus", "../shared/regressions"] {
        let d = root.join(shared);
        if d.is_dir() {
            dirs.push(d);
        } else {
            notes.push(format!("skipped: {} not found", d.display()));
        }
    }
    (dirs, notes)
}

/// Numbers that parsers get wrong: zero, signs, the ends of the integer types, overflowing and
/// underflowing floats, non-finite values and digit strings no type holds.
pub const EXTREMES: &[&str] = &[
    "0",
    "-1",
    "-0",
    "1",
    "1e308",
    "-1e308",
    "1e309",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e-9",
    "1e-320",
    "2147483647",
    "2147483648",
    "-2147483649",
    "4294967295",
    "4294967296",
    "9223372036854775808",
    "18446744073709551616",
    "1e18",
    "1e9",
    "-1e9",
    "65536",
    "0.5",
    "3",
    "999999999999999999999999999999999999999999999999999999999999999999999999",
    "0x7fffffff",
    "1e",
    ".",
    "-",
];

/// Tokens worth inserting into any text input.
const TOKENS: &[&str] = &[
    "\n",
    "\r\n",
    "\0",
    " ",
    "\t",
    ",",
    ";",
    "\"",
    "'",
    "<",
    ">",
    "</",
    "/>",
    "=\"",
    "&amp;",
    "&#0;",
    "&#x110000;",
    "<![CDATA[",
    "]]>",
    "<!--",
    "-->",
    "[",
    "]",
    "[[",
    "=",
    "#",
    "%",
    "\u{feff}",
    "\u{fffd}",
    "é",
    "1e308",
    "NaN",
    "-",
];

/// Little-endian 32-bit values worth writing over four bytes of a binary input.
const WORDS: &[u32] = &[
    0,
    1,
    0xffff_ffff,
    0x7fff_ffff,
    0x8000_0000,
    0x4000_0000,
    0x0100_0000,
    0xffff,
    0x10000,
    0x7fc0_0000, // f32 NaN
    0x7f80_0000, // f32 +inf
    0xff80_0000, // f32 -inf
    0x7f7f_ffff, // f32 max
    0x0000_0001, // f32 smallest subnormal
];

/// What a target is: a name, which seeds it takes, the tokens it knows, and the function that
/// runs one input (`true` when the input was read without error).
pub struct Target {
    /// Name, used on the command line and in findings' file names.
    pub name: &'static str,
    /// What the target reads, for the report.
    pub about: &'static str,
    /// Whether a seed (by extension and content) is one of this target's.
    pub accepts: fn(&Seed) -> bool,
    /// Tokens of the format, inserted by one mutation.
    pub dict: &'static [&'static str],
    /// Runs one input; `Ok`-like results return `true`.
    pub run: fn(&Input<'_>) -> bool,
    /// Executions per CI run (see `tests/fuzz_stable.rs`).
    pub ci_execs: u64,
}

/// One input handed to a target: the bytes, the extension of the seed it came from, and a
/// private scratch folder for the targets that read files by path.
pub struct Input<'a> {
    /// The mutated bytes.
    pub bytes: &'a [u8],
    /// Extension of the seed (lower case, no dot).
    pub ext: &'a str,
    /// A folder the target may write into.
    pub scratch: &'a Path,
}

impl Input<'_> {
    /// Writes the bytes to `scratch/input.EXT` (the seed's extension, or `ext` when given) and
    /// returns the path, for the readers that take a file.
    pub fn file(&self, ext: Option<&str>) -> PathBuf {
        let ext = ext.unwrap_or(self.ext);
        let p = self.scratch.join(format!("input.{ext}"));
        if let Err(e) = std::fs::write(&p, self.bytes) {
            panic!("fuzz scratch file {} cannot be written: {e}", p.display());
        }
        p
    }

    /// The bytes as text (invalid UTF-8 replaced), for the readers that take `&str`.
    pub fn text(&self) -> std::borrow::Cow<'_, str> {
        String::from_utf8_lossy(self.bytes)
    }
}

/// A scratch folder for the targets that read files: in memory (`/dev/shm`) where there is
/// one, as writing the same file again and again on a disk file system waits for the disk.
pub fn scratch_dir() -> std::io::Result<tempfile::TempDir> {
    tempfile::Builder::new()
        .prefix("conduit-fuzz")
        .tempdir_in("/dev/shm")
        .or_else(|_| tempfile::tempdir())
}

/// Length cap of a mutated input.
const MAX_INPUT: usize = 4 << 20;

/// Mutates `seed` (with `pool`, the target's other seeds, for splicing) into `out`.
pub fn mutate(rng: &mut Rng, seed: &Seed, pool: &[&Seed], dict: &[&str], out: &mut Vec<u8>) {
    out.clear();
    if let Some(entries) = &seed.entries
        && !entries.is_empty()
        && !rng.one_in(4)
    {
        mutate_zip(rng, entries, dict, out);
        return;
    }
    out.extend_from_slice(&seed.bytes);
    let rounds = 1 + rng.below(4).min(rng.below(4));
    for _ in 0..rounds {
        mutate_once(rng, pool, dict, out);
    }
    out.truncate(MAX_INPUT);
}

/// One mutation of `buf` in place.
fn mutate_once(rng: &mut Rng, pool: &[&Seed], dict: &[&str], buf: &mut Vec<u8>) {
    let len = buf.len();
    match rng.below(14) {
        // Flip one to eight bits.
        0 if len > 0 => {
            for _ in 0..rng.size(8) {
                let i = rng.below(len);
                buf[i] ^= 1 << rng.below(8);
            }
        }
        // Set a byte to an interesting or random value.
        1 if len > 0 => {
            let i = rng.below(len);
            buf[i] = *rng.pick(&[
                0, 0xff, 0x7f, 0x80, b'<', b'>', b'"', b'\n', b' ', b'-', b'.', b'e',
            ]) ^ if rng.one_in(3) {
                rng.below(256) as u8
            } else {
                0
            };
        }
        // Insert random bytes.
        2 => {
            let at = rng.below(len + 1);
            let n = rng.size(16);
            let bytes: Vec<u8> = (0..n).map(|_| rng.below(256) as u8).collect();
            buf.splice(at..at, bytes);
        }
        // Delete a range.
        3 if len > 0 => {
            let at = rng.below(len);
            let max = if rng.one_in(8) { len } else { 64 };
            let n = rng.size(max).min(len - at);
            buf.drain(at..at + n);
        }
        // Duplicate a chunk, sometimes many times (deep nesting, long lines, many records).
        4 if len > 0 => {
            let at = rng.below(len);
            let n = rng.size(256).min(len - at);
            let chunk = buf[at..at + n].to_vec();
            let times = if rng.one_in(4) { rng.size(512) } else { 1 };
            let to = rng.below(len + 1);
            let rep: Vec<u8> = chunk
                .iter()
                .copied()
                .cycle()
                .take(n * times)
                .take(MAX_INPUT)
                .collect();
            buf.splice(to..to, rep);
        }
        // Splice with another seed: this one's head, the other's tail.
        5 if !pool.is_empty() => {
            let other = &rng.pick(pool).bytes;
            let cut = rng.below(len + 1);
            let from = rng.below(other.len() + 1);
            buf.truncate(cut);
            buf.extend_from_slice(&other[from..]);
        }
        // Replace a number with an extreme value.
        6 | 7 => replace_number(rng, buf),
        // Truncate.
        8 if len > 0 => buf.truncate(rng.below(len)),
        // Insert a token of the format or of text formats in general.
        9 => {
            let tok = if !dict.is_empty() && rng.one_in(2) {
                *rng.pick(dict)
            } else {
                *rng.pick(TOKENS)
            };
            let at = rng.below(len + 1);
            buf.splice(at..at, tok.bytes());
        }
        // Overwrite four bytes with an interesting little-endian word (binary formats).
        10 if len >= 4 => {
            let at = rng.below(len - 3);
            let w = rng.pick(WORDS).to_le_bytes();
            buf[at..at + 4].copy_from_slice(&w);
        }
        // Duplicate, delete or swap whole lines.
        11 => line_mutation(rng, buf),
        // Overwrite a chunk with a copy of another part of the input.
        12 if len > 1 => {
            let n = rng.size(64).min(len / 2);
            let from = rng.below(len - n + 1);
            let to = rng.below(len - n + 1);
            let chunk = buf[from..from + n].to_vec();
            buf[to..to + n].copy_from_slice(&chunk);
        }
        // Insert an extreme number at a random place.
        13 => {
            let at = rng.below(len + 1);
            buf.splice(at..at, rng.pick(EXTREMES).bytes());
        }
        _ => {
            if len > 0 {
                let i = rng.below(len);
                buf[i] = buf[i].wrapping_add(1);
            }
        }
    }
}

/// Replaces the first number at or after a random position with one of [`EXTREMES`].
fn replace_number(rng: &mut Rng, buf: &mut Vec<u8>) {
    let len = buf.len();
    if len == 0 {
        buf.extend_from_slice(rng.pick(EXTREMES).as_bytes());
        return;
    }
    let start = rng.below(len);
    let Some(first) = (start..len)
        .chain(0..start)
        .find(|&i| buf[i].is_ascii_digit())
    else {
        return;
    };
    let mut s = first;
    while s > 0 && matches!(buf[s - 1], b'0'..=b'9' | b'.' | b'-' | b'+') {
        s -= 1;
    }
    let mut e = first;
    while e < len && matches!(buf[e], b'0'..=b'9' | b'.' | b'e' | b'E' | b'-' | b'+') {
        e += 1;
    }
    let with = rng.pick(EXTREMES);
    buf.splice(s..e, with.bytes());
}

/// Duplicates a line many times, deletes one or swaps two.
fn line_mutation(rng: &mut Rng, buf: &mut Vec<u8>) {
    let starts: Vec<usize> = std::iter::once(0)
        .chain(
            buf.iter()
                .enumerate()
                .filter(|(_, b)| **b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .filter(|&i| i < buf.len())
        .collect();
    if starts.is_empty() {
        return;
    }
    let line = |i: usize| -> (usize, usize) {
        let s = starts[i];
        let e = starts.get(i + 1).copied().unwrap_or(buf.len());
        (s, e)
    };
    let (s, e) = line(rng.below(starts.len()));
    match rng.below(3) {
        0 => {
            let text = buf[s..e].to_vec();
            let max = if rng.one_in(4) { 4096 } else { 8 };
            let times = rng.size(max);
            let mut rep = Vec::with_capacity(text.len().saturating_mul(times).min(MAX_INPUT));
            for _ in 0..times {
                rep.extend_from_slice(&text);
                if !text.ends_with(b"\n") {
                    rep.push(b'\n');
                }
                if rep.len() > MAX_INPUT {
                    break;
                }
            }
            buf.splice(e..e, rep);
        }
        1 => {
            buf.drain(s..e);
        }
        _ => {
            let (s2, e2) = line(rng.below(starts.len()));
            if e <= s2 {
                let second = buf[s2..e2].to_vec();
                let first = buf[s..e].to_vec();
                buf.splice(s2..e2, first);
                buf.splice(s..e, second);
            }
        }
    }
}

/// Mutates the entries of a zip package (mostly the XML of one part, sometimes the entry list)
/// and zips them again.
fn mutate_zip(rng: &mut Rng, entries: &[(String, Vec<u8>)], dict: &[&str], out: &mut Vec<u8>) {
    let mut entries: Vec<(String, Vec<u8>)> = entries.to_vec();
    match rng.below(10) {
        0 if entries.len() > 1 => {
            entries.remove(rng.below(entries.len()));
        }
        1 => {
            let i = rng.below(entries.len());
            let copy = entries[i].clone();
            entries.push(copy);
        }
        2 => {
            let i = rng.below(entries.len());
            let mut name = entries[i].0.clone().into_bytes();
            mutate_once(
                rng,
                &[],
                &["/", "\\", "..", "%20", ".model", "3D/"],
                &mut name,
            );
            entries[i].0 = String::from_utf8_lossy(&name).into_owned();
        }
        _ => {
            // Prefer the models, then any XML part.
            let models: Vec<usize> = (0..entries.len())
                .filter(|&i| entries[i].0.ends_with(".model"))
                .collect();
            let i = if !models.is_empty() && !rng.one_in(4) {
                *rng.pick(&models)
            } else {
                rng.below(entries.len())
            };
            let data = &mut entries[i].1;
            for _ in 0..1 + rng.below(3) {
                mutate_once(rng, &[], dict, data);
            }
            data.truncate(MAX_INPUT);
        }
    }
    let method = if rng.one_in(4) {
        zip::CompressionMethod::Deflated
    } else {
        zip::CompressionMethod::Stored
    };
    let opts = zip::write::SimpleFileOptions::default().compression_method(method);
    let mut w = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for (name, data) in &entries {
        if w.start_file(name.as_str(), opts).is_err() || w.write_all(data).is_err() {
            // A name the writer refuses (e.g. a duplicate): leave that entry out.
            continue;
        }
    }
    match w.finish() {
        Ok(c) => out.extend_from_slice(&c.into_inner()),
        Err(_) => out.extend_from_slice(b"PK\x03\x04"),
    }
}

/// Thresholds of one run.
#[derive(Debug, Clone)]
pub struct Limits {
    /// An execution longer than this is counted as slow.
    pub slow: Duration,
    /// An execution longer than this is a finding; the watchdog stops the process once one has
    /// run this long without returning.
    pub hang: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            slow: Duration::from_secs(1),
            hang: Duration::from_secs(10),
        }
    }
}

/// A panic, hang or huge allocation, with the file its input was saved to.
#[derive(Debug, Clone)]
pub struct Finding {
    /// "panic", "hang" or "alloc".
    pub kind: &'static str,
    /// The panic message and place, or the time taken, or the size asked for.
    pub message: String,
    /// Index of the execution.
    pub exec: u64,
    /// Where the input was saved (`None` when no findings folder was given).
    pub file: Option<PathBuf>,
    /// The input.
    pub input: Vec<u8>,
}

/// What one target's run did.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// The target.
    pub target: String,
    /// Seeds it drew from.
    pub seeds: usize,
    /// Executions run.
    pub execs: u64,
    /// Executions whose input was read without error.
    pub ok: u64,
    /// Executions over [`Limits::slow`].
    pub slow: u64,
    /// The longest execution.
    pub slowest: Duration,
    /// Wall time of the run.
    pub elapsed: Duration,
    /// Peak resident memory of the process during the run, in KiB (0 where unknown).
    pub peak_kib: u64,
    /// Panics, hangs and huge allocations.
    pub findings: Vec<Finding>,
}

impl Report {
    /// Executions per second.
    pub fn rate(&self) -> f64 {
        self.execs as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    /// Findings of one kind.
    pub fn count(&self, kind: &str) -> usize {
        self.findings.iter().filter(|f| f.kind == kind).count()
    }

    /// One line: executions, rate, findings, slowest, memory.
    pub fn line(&self) -> String {
        format!(
            "{:<14} {:>9} execs {:>9.0}/s  ok {:>5.1}%  panics {}  hangs {}  allocs {}  slow {}  slowest {:.3} s  peak {:.1} MiB  ({} seeds)",
            self.target,
            self.execs,
            self.rate(),
            100.0 * self.ok as f64 / self.execs.max(1) as f64,
            self.count("panic"),
            self.count("hang"),
            self.count("alloc"),
            self.slow,
            self.slowest.as_secs_f64(),
            self.peak_kib as f64 / 1024.0,
            self.seeds,
        )
    }
}

/// Allocations over this many bytes are findings (when the binary's allocator reports them
/// through [`HUGE_ALLOC`]).
pub const HUGE_BYTES: usize = 512 << 20;

/// The largest allocation over [`HUGE_BYTES`] seen since the last execution started; set by a
/// counting allocator (`examples/fuzz_stable.rs`), 0 when there is none.
pub static HUGE_ALLOC: AtomicUsize = AtomicUsize::new(0);

/// Index of the execution running now (of the last target started), for the allocator's
/// message.
pub static CURRENT_EXEC: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static QUIET: Cell<bool> = const { Cell::new(false) };
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Installs (once) a panic hook that records the message of a panic inside a target instead of
/// printing it, and leaves every other panic to the hook that was there before.
fn install_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if QUIET.with(Cell::get) {
                let msg = info
                    .payload()
                    .downcast_ref::<&str>()
                    .map(|s| (*s).to_owned())
                    .or_else(|| info.payload().downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                let at = info
                    .location()
                    .map(|l| format!("{}:{}", l.file(), l.line()))
                    .unwrap_or_default();
                LAST_PANIC.with(|p| *p.borrow_mut() = format!("{msg} at {at}"));
            } else {
                previous(info);
            }
        }));
    });
}

/// Resets the process's peak resident memory (Linux `clear_refs`); false where unsupported.
pub fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The process's peak resident memory in KiB (`VmHWM`), 0 where unknown.
pub fn peak_memory_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        })
        .unwrap_or(0)
}

/// The input being executed, for the watchdog.
struct Current {
    started: Option<Instant>,
    exec: u64,
    input: Vec<u8>,
    ext: String,
}

/// Runs targets: the seeds, the run's seed, the thresholds and where findings go.
pub struct Runner {
    /// All seeds; each target takes those it accepts.
    pub seeds: Vec<Seed>,
    /// Seed of the run: with a target's name and an execution's index it fixes the input.
    pub seed: u64,
    /// Thresholds.
    pub limits: Limits,
    /// Folder findings are written to (created when needed); `None` keeps them in memory.
    pub findings: Option<PathBuf>,
}

impl Runner {
    /// The seeds `target` takes (all seeds when it accepts none, so that it still runs).
    pub fn pool<'a>(&'a self, target: &Target) -> Vec<&'a Seed> {
        let own: Vec<&Seed> = self.seeds.iter().filter(|s| (target.accepts)(s)).collect();
        if own.is_empty() {
            self.seeds.iter().collect()
        } else {
            own
        }
    }

    /// The input of execution `exec` of `target` and the extension of its seed: one seed in 16
    /// as it is, the others mutated.
    pub fn input(&self, target: &Target, pool: &[&Seed], exec: u64, out: &mut Vec<u8>) -> String {
        let mut rng = Rng::new(
            self.seed ^ fnv(target.name.as_bytes()) ^ exec.wrapping_mul(0x2545_f491_4f6c_dd1d),
        );
        rng.next_u64();
        if pool.is_empty() {
            out.clear();
            return String::new();
        }
        let seed = *rng.pick(pool);
        if rng.one_in(16) {
            out.clear();
            out.extend_from_slice(&seed.bytes);
        } else {
            mutate(&mut rng, seed, pool, target.dict, out);
        }
        seed.ext.clone()
    }

    /// Runs `execs` executions of `target`, with `scratch` as its private folder.
    pub fn run(&self, target: &Target, execs: u64, scratch: &Path) -> Report {
        install_hook();
        let pool = self.pool(target);
        let current = Arc::new(Mutex::new(Current {
            started: None,
            exec: 0,
            input: Vec::new(),
            ext: String::new(),
        }));
        let done = Arc::new(AtomicBool::new(false));
        let watchdog = {
            let current = Arc::clone(&current);
            let done = Arc::clone(&done);
            let hang = self.limits.hang;
            let findings = self.findings.clone();
            let name = target.name;
            std::thread::spawn(move || watch(&current, &done, hang, findings.as_deref(), name))
        };
        reset_peak_memory();
        let mut report = Report {
            target: target.name.to_owned(),
            seeds: pool.len(),
            ..Report::default()
        };
        let mut buf = Vec::new();
        let start = Instant::now();
        for exec in 0..execs {
            let ext = self.input(target, &pool, exec, &mut buf);
            if let Ok(mut c) = current.lock() {
                c.input.clear();
                c.input.extend_from_slice(&buf);
                c.ext.clone_from(&ext);
                c.exec = exec;
                c.started = Some(Instant::now());
            }
            HUGE_ALLOC.store(0, Ordering::Relaxed);
            CURRENT_EXEC.store(exec, Ordering::Relaxed);
            let input = Input {
                bytes: &buf,
                ext: &ext,
                scratch,
            };
            let t0 = Instant::now();
            QUIET.with(|q| q.set(true));
            let result = catch_unwind(AssertUnwindSafe(|| (target.run)(&input)));
            QUIET.with(|q| q.set(false));
            let took = t0.elapsed();
            if let Ok(mut c) = current.lock() {
                c.started = None;
            }
            report.execs += 1;
            report.slowest = report.slowest.max(took);
            if took > self.limits.slow {
                report.slow += 1;
                // The first few slow inputs are kept to look at; they are not findings.
                if report.slow <= 5
                    && let Some(d) = self.findings.as_deref()
                {
                    save(d, "slow", target.name, &buf, &ext);
                }
            }
            match result {
                Ok(true) => report.ok += 1,
                Ok(false) => {}
                Err(_) => {
                    let msg = LAST_PANIC.with(|p| std::mem::take(&mut *p.borrow_mut()));
                    self.record(&mut report, "panic", msg, exec, &buf, &ext);
                }
            }
            if took > self.limits.hang {
                let msg = format!("{:.1} s", took.as_secs_f64());
                self.record(&mut report, "hang", msg, exec, &buf, &ext);
            }
            let huge = HUGE_ALLOC.swap(0, Ordering::Relaxed);
            if huge > 0 {
                let msg = format!("allocation of {huge} bytes");
                self.record(&mut report, "alloc", msg, exec, &buf, &ext);
            }
        }
        report.elapsed = start.elapsed();
        report.peak_kib = peak_memory_kib();
        done.store(true, Ordering::Relaxed);
        let _ = watchdog.join();
        report
    }

    /// Keeps a finding (at most 20 per message and kind, the rest only counted by the caller)
    /// and saves its input.
    fn record(
        &self,
        report: &mut Report,
        kind: &'static str,
        message: String,
        exec: u64,
        input: &[u8],
        ext: &str,
    ) {
        let same = report
            .findings
            .iter()
            .filter(|f| f.kind == kind && f.message == message)
            .count();
        let file = if same < 20 {
            self.findings
                .as_deref()
                .and_then(|d| save(d, kind, report.target.as_str(), input, ext))
        } else {
            None
        };
        report.findings.push(Finding {
            kind,
            message,
            exec,
            file,
            input: if same < 20 {
                input.to_vec()
            } else {
                Vec::new()
            },
        });
    }
}

/// Runs one input through `target` as the runner does: `Ok(read)` when it returned (whether
/// the input was read), `Err(message)` when it panicked.
pub fn replay(target: &Target, bytes: &[u8], ext: &str, scratch: &Path) -> Result<bool, String> {
    install_hook();
    let input = Input {
        bytes,
        ext,
        scratch,
    };
    QUIET.with(|q| q.set(true));
    let result = catch_unwind(AssertUnwindSafe(|| (target.run)(&input)));
    QUIET.with(|q| q.set(false));
    result.map_err(|_| LAST_PANIC.with(|p| std::mem::take(&mut *p.borrow_mut())))
}

/// Writes a finding's input to `dir/KIND-TARGET-HASH.EXT`; returns the path.
pub fn save(dir: &Path, kind: &str, target: &str, input: &[u8], ext: &str) -> Option<PathBuf> {
    std::fs::create_dir_all(dir).ok()?;
    let ext = if ext.is_empty() { "bin" } else { ext };
    let p = dir.join(format!("{kind}-{target}-{:016x}.{ext}", fnv(input)));
    std::fs::write(&p, input).ok()?;
    Some(p)
}

/// The watchdog: once an execution has run past `hang`, saves its input and ends the process
/// (an in-process target cannot be interrupted).
fn watch(
    current: &Mutex<Current>,
    done: &AtomicBool,
    hang: Duration,
    findings: Option<&Path>,
    target: &str,
) {
    while !done.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(100));
        let Ok(c) = current.lock() else { return };
        if let Some(t) = c.started
            && t.elapsed() > hang
        {
            let file = findings.and_then(|d| save(d, "hang", target, &c.input, &c.ext));
            eprintln!(
                "{target}: execution {} still running after {:.0} s: a hang; input {}",
                c.exec,
                hang.as_secs_f64(),
                file.map_or_else(
                    || format!("of {} bytes (no findings folder)", c.input.len()),
                    |p| format!("saved to {}", p.display())
                ),
            );
            std::process::exit(3);
        }
    }
}
