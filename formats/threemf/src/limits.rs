//! Resource limits for reading untrusted packages.

/// Upper bounds the reader (and [`crate::Package::flatten`]) enforce, so a hostile or broken
/// file fails with [`crate::ThreeMfError::LimitExceeded`] or
/// [`crate::ThreeMfError::CompressionRatio`] instead of exhausting memory or time.
///
/// Sizes are checked while inflating: parts are read through `Read::take` and the bytes that
/// actually come out are counted. The sizes in ZIP headers are never trusted for allocation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Limits {
    /// Most ZIP entries (files and folders) a package may list. Default 10 000: real packages
    /// have tens of parts (a sliced production file ~60); the central directory of a hostile
    /// archive can claim millions.
    pub max_archive_entries: usize,
    /// Most bytes inflated from all parts read, together. Default 1 GiB: about 15 million
    /// triangles of typical 3MF XML, well above any model a printer can take, and still within
    /// the memory of a developer machine.
    pub max_uncompressed_bytes: u64,
    /// Most bytes a part may inflate to per compressed byte, checked once a part has produced
    /// more than [`RATIO_CHECK_FLOOR`] bytes. Default 200: mesh XML deflates 4-20x and very
    /// repetitive XML stays below ~100x, while a deflate bomb reaches ~1000x.
    pub max_compression_ratio: u64,
    /// Most vertices in the whole package (and in a flattened result). Default 50 million
    /// (1.2 GB as `[f64; 3]`).
    pub max_vertices: usize,
    /// Most triangles in the whole package (and in a flattened result). Default 100 million.
    pub max_triangles: usize,
    /// Most resources (objects, property groups, slice stacks...) in the whole package.
    /// Default 1 million.
    pub max_objects: usize,
    /// Deepest nesting of components (also bounds component cycles). Default 32: real
    /// assemblies nest a handful of levels. [`crate::Package::flatten`] never follows more than
    /// 4096 levels, whatever this says, to keep its recursion stack-safe.
    pub max_component_depth: usize,
}

/// Parts smaller than this (16 MiB) are never rejected for their compression ratio alone:
/// small, very regular parts (an all-white texture, a repetitive slice stack) can legitimately
/// compress far better than mesh XML, and their absolute size is harmless.
pub const RATIO_CHECK_FLOOR: u64 = 16 * 1024 * 1024;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_archive_entries: 10_000,
            max_uncompressed_bytes: 1 << 30,
            max_compression_ratio: 200,
            max_vertices: 50_000_000,
            max_triangles: 100_000_000,
            max_objects: 1_000_000,
            max_component_depth: 32,
        }
    }
}
