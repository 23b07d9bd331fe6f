//! Writing output files without clobbering anything: where an output path really leads, refusing
//! an output that is one of the run's inputs, and writing several files all or nothing.
//!
//! Place in the pipeline: the last step of every command that writes files (`convert`'s meshes,
//! `slice`'s G-code and report, `preview`'s layer files, …). The stages build their outputs in
//! memory; this module only decides how the bytes reach the file system:
//!
//! - a regular file (or a path that does not exist yet) is written to a temporary file in the
//!   same folder and renamed over the target, so a failed run never leaves a partial file;
//! - a symbolic link is followed to its target, which is written that way (the link is kept);
//! - anything else that exists (a device such as `/dev/null`, a FIFO) is opened and written
//!   directly — renaming over it would replace the device with a regular file;
//! - an output that is the same file as an input (same device and inode, so hard links and other
//!   spellings of the path count) is refused, unless the command rewrites that input on purpose
//!   ([`OutputSet::add_in_place`]);
//! - [`OutputSet`] stages every file of a command before renaming any, and removes the staged
//!   files when one fails, so nothing of a failed set is left behind.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Symbolic links followed before giving up (Linux's limit).
const MAX_LINKS: usize = 40;

/// An output that could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The output is the same file as one of the run's inputs.
    #[error(
        "{}: refusing to overwrite the input {} (choose another output path)",
        output.display(),
        input.display()
    )]
    SameAsInput {
        /// The output path as given.
        output: PathBuf,
        /// The input path as given.
        input: PathBuf,
    },
    /// Two outputs of one run lead to the same file.
    #[error("{}: given twice as an output of this run", path.display())]
    Duplicate {
        /// The output path as given (the second time).
        path: PathBuf,
    },
    /// The folder of the output does not exist.
    #[error("{}: cannot write: folder {} does not exist", path.display(), folder.display())]
    NoFolder {
        /// The output path as given.
        path: PathBuf,
        /// The missing folder.
        folder: PathBuf,
    },
    /// A file system error.
    #[error("{}: cannot write: {error}", path.display())]
    Io {
        /// The output path as given.
        path: PathBuf,
        /// The error, without the path of any temporary file.
        error: io::Error,
    },
}

impl OutputError {
    fn io(path: &Path, error: io::Error) -> OutputError {
        OutputError::Io {
            path: path.to_path_buf(),
            error: plain(error),
        }
    }
}

/// Where an output path leads.
#[derive(Debug)]
enum Target {
    /// A regular file, existing or not, written through a temporary file and a rename. The path
    /// has its symbolic links resolved (a link is kept and its target replaced).
    Regular(PathBuf),
    /// An existing file that is not a regular file (a device, a FIFO): written directly.
    Special(PathBuf),
}

impl Target {
    fn path(&self) -> &Path {
        match self {
            Target::Regular(p) | Target::Special(p) => p,
        }
    }
}

/// Follows `path`'s symbolic links (also a dangling one: its target is created) and says how
/// the file it leads to is written.
fn resolve(path: &Path) -> io::Result<Target> {
    // The kernel follows the links first: `/dev/fd/N` and `/dev/stdout` are links whose
    // text (`pipe:[…]`) names no path, yet open to the pipe.
    match fs::metadata(path) {
        Ok(m) if m.is_file() => {
            let linked = fs::symlink_metadata(path).is_ok_and(|l| l.file_type().is_symlink());
            return Ok(Target::Regular(if linked {
                fs::canonicalize(path)?
            } else {
                path.to_path_buf()
            }));
        }
        Ok(m) if m.is_dir() => return Err(io::Error::other("it is a folder")),
        Ok(_) => return Ok(Target::Special(path.to_path_buf())),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    // Nothing there yet, or a dangling link: the file its last link names is created.
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) => dir.join(link),
                    None => link,
                };
            }
            Ok(_) => return Ok(Target::Regular(p)),
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Target::Regular(p)),
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// The folder a regular file is written in.
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The error without decorations naming a temporary file (`tempfile` appends "at path …").
fn plain(e: io::Error) -> io::Error {
    if e.raw_os_error().is_some() {
        return e;
    }
    let inner = e
        .get_ref()
        .and_then(|x| x.source())
        .and_then(|s| s.downcast_ref::<io::Error>())
        .and_then(io::Error::raw_os_error);
    if let Some(code) = inner {
        return io::Error::from_raw_os_error(code);
    }
    // tempfile's wrapper of an operating system error has no source to unwrap: its text is
    // the error's, then ` at path "<temporary file>"`.
    let text = e.get_ref().map(ToString::to_string).unwrap_or_default();
    if let Some((cause, _)) = text.rsplit_once(" at path \"") {
        return io::Error::new(e.kind(), cause.to_owned());
    }
    if e.get_ref().is_some_and(|x| x.source().is_some()) {
        io::Error::from(e.kind())
    } else {
        e
    }
}

/// Who a file is, for telling whether two paths name the same file.
#[derive(Debug, Clone, PartialEq, Eq)]
struct FileId {
    #[cfg(unix)]
    dev_ino: (u64, u64),
    #[cfg(not(unix))]
    canonical: PathBuf,
}

impl FileId {
    /// The identity of an existing file (symbolic links followed).
    fn of(path: &Path) -> Option<FileId> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let m = fs::metadata(path).ok()?;
            Some(FileId {
                dev_ino: (m.dev(), m.ino()),
            })
        }
        #[cfg(not(unix))]
        {
            Some(FileId {
                canonical: fs::canonicalize(path).ok()?,
            })
        }
    }
}

/// A temporary file beside `target` that gets `target`'s permissions when it exists, or those of
/// an ordinary new file (0666 less the umask); temporary files are private (0600) by default.
fn temp_beside(target: &Path, given: &Path) -> Result<tempfile::NamedTempFile, OutputError> {
    let dir = folder_of(target);
    if !dir.is_dir() {
        return Err(OutputError::NoFolder {
            path: given.to_path_buf(),
            folder: dir,
        });
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".conduit-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = fs::metadata(target).map_or(0o666, |m| m.permissions().mode() & 0o7777);
        builder.permissions(fs::Permissions::from_mode(mode));
    }
    builder
        .tempfile_in(&dir)
        .map_err(|e| OutputError::io(given, e))
}

/// Writes `path`: `fill` writes into a temporary file in the target's folder, which is renamed
/// over the target only when `fill` succeeds (and no stop was requested, see
/// [`crate::interrupt`]). A symbolic link is followed (the link is kept); a device or FIFO is
/// written directly. Errors name no temporary file; a missing folder is said as such.
pub fn write_atomically<F, E>(path: &Path, fill: F) -> Result<(), E>
where
    F: FnOnce(&mut fs::File) -> Result<(), E>,
    E: From<io::Error>,
{
    let target = resolve(path).map_err(plain)?;
    match target {
        Target::Special(p) => {
            let mut f = fs::OpenOptions::new().write(true).open(&p)?;
            fill(&mut f)?;
            f.flush()?;
            Ok(())
        }
        Target::Regular(p) => {
            let mut tmp = temp_beside(&p, path).map_err(|e| match e {
                OutputError::NoFolder { folder, .. } => io::Error::new(
                    io::ErrorKind::NotFound,
                    format!("folder {} does not exist", folder.display()),
                ),
                OutputError::Io { error, .. } => error,
                other => io::Error::other(other.to_string()),
            })?;
            fill(tmp.as_file_mut())?;
            tmp.as_file_mut().sync_all().map_err(plain)?;
            if crate::interrupt::requested() {
                return Err(crate::interrupt::error().into());
            }
            tmp.persist(&p).map_err(|e| plain(e.error))?;
            Ok(())
        }
    }
}

/// One staged output of an [`OutputSet`].
struct Staged {
    /// The path as given.
    path: PathBuf,
    /// The file it leads to.
    target: PathBuf,
    /// How the bytes get there.
    how: Staging,
}

enum Staging {
    /// Written, synced, waiting for its rename.
    Temp(tempfile::NamedTempFile),
    /// A device or FIFO: the bytes, written when the set is committed.
    Direct(Vec<u8>),
}

/// The output files of one run, written all or nothing: each [`add`](OutputSet::add) writes its
/// file to a temporary file beside the target; [`commit`](OutputSet::commit) renames them all.
/// When an `add` or the commit fails, or the set is dropped without a commit, the temporary
/// files are removed and no target is touched. (A rename in the same folder failing after
/// another succeeded would leave the earlier ones; renames fail only when the folder itself
/// changes under the run.) Outputs that are the same file as a registered input, or as another
/// output of the set, are refused.
#[derive(Default)]
pub struct OutputSet {
    inputs: Vec<(PathBuf, FileId)>,
    staged: Vec<Staged>,
}

impl OutputSet {
    /// An empty set whose outputs may not be any of `inputs` (paths that do not exist are
    /// ignored: they cannot be overwritten).
    pub fn new<I, P>(inputs: I) -> OutputSet
    where
        I: IntoIterator<Item = P>,
        P: AsRef<Path>,
    {
        let mut set = OutputSet::default();
        for p in inputs {
            set.input(p.as_ref());
        }
        set
    }

    /// Registers one more input that no output may overwrite.
    pub fn input(&mut self, path: &Path) {
        if let Some(id) = FileId::of(path) {
            self.inputs.push((path.to_path_buf(), id));
        }
    }

    /// Checks that `path` can be an output of the set: not an input, not an output already
    /// added, in a folder that exists. Commands call it for their outputs before the work, so
    /// a wrong path fails before a long run.
    pub fn check(&self, path: &Path) -> Result<(), OutputError> {
        self.checked(path, false).map(|_| ())
    }

    fn checked(&self, path: &Path, in_place: bool) -> Result<Target, OutputError> {
        let target = resolve(path).map_err(|e| OutputError::io(path, e))?;
        if let Target::Regular(p) = &target {
            let folder = folder_of(p);
            if !folder.is_dir() {
                return Err(OutputError::NoFolder {
                    path: path.to_path_buf(),
                    folder,
                });
            }
            if let Some(id) = FileId::of(p) {
                if !in_place {
                    if let Some((input, _)) = self.inputs.iter().find(|(_, i)| *i == id) {
                        return Err(OutputError::SameAsInput {
                            output: path.to_path_buf(),
                            input: input.clone(),
                        });
                    }
                }
                if self
                    .staged
                    .iter()
                    .any(|s| FileId::of(&s.target) == Some(id.clone()))
                {
                    return Err(OutputError::Duplicate {
                        path: path.to_path_buf(),
                    });
                }
            }
            let key = same_place(p);
            if self.staged.iter().any(|s| same_place(&s.target) == key) {
                return Err(OutputError::Duplicate {
                    path: path.to_path_buf(),
                });
            }
        }
        Ok(target)
    }

    /// Stages `bytes` as the content of `path`.
    pub fn add(&mut self, path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        let target = self.checked(path, false)?;
        self.stage(path, target, bytes)
    }

    /// Stages `bytes` as the new content of `path`, which may be an input: a command that
    /// rewrites its input on purpose (`postprocess`, the slicer plugin).
    pub fn add_in_place(&mut self, path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        let target = self.checked(path, true)?;
        self.stage(path, target, bytes)
    }

    fn stage(&mut self, path: &Path, target: Target, bytes: &[u8]) -> Result<(), OutputError> {
        let how = match &target {
            Target::Special(_) => Staging::Direct(bytes.to_vec()),
            Target::Regular(p) => {
                let mut tmp = temp_beside(p, path)?;
                let f = tmp.as_file_mut();
                f.write_all(bytes)
                    .and_then(|()| f.sync_all())
                    .map_err(|e| OutputError::io(path, e))?;
                Staging::Temp(tmp)
            }
        };
        self.staged.push(Staged {
            path: path.to_path_buf(),
            target: target.path().to_path_buf(),
            how,
        });
        Ok(())
    }

    /// Writes the set: devices and FIFOs first (a failure there leaves every regular target
    /// untouched), then every staged file renamed over its target.
    pub fn commit(self) -> Result<(), OutputError> {
        if crate::interrupt::requested() {
            let path = self
                .staged
                .first()
                .map_or_else(PathBuf::new, |s| s.path.clone());
            return Err(OutputError::io(&path, crate::interrupt::error()));
        }
        let mut temps = Vec::with_capacity(self.staged.len());
        for s in self.staged {
            match s.how {
                Staging::Direct(bytes) => {
                    fs::OpenOptions::new()
                        .write(true)
                        .open(&s.target)
                        .and_then(|mut f| f.write_all(&bytes).and_then(|()| f.flush()))
                        .map_err(|e| OutputError::io(&s.path, e))?;
                }
                Staging::Temp(tmp) => temps.push((s.path, s.target, tmp)),
            }
        }
        for (path, target, tmp) in temps {
            tmp.persist(&target)
                .map_err(|e| OutputError::io(&path, e.error))?;
        }
        Ok(())
    }
}

/// A regular file's path with its folder canonicalised, to compare outputs that do not exist
/// yet.
fn same_place(path: &Path) -> PathBuf {
    let folder = fs::canonicalize(folder_of(path)).unwrap_or_else(|_| folder_of(path));
    match path.file_name() {
        Some(name) => folder.join(name),
        None => folder,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_add_leaves_nothing_and_touches_no_target() {
        let dir = tempfile::tempdir().expect("temp dir");
        let a = dir.path().join("a.txt");
        fs::write(&a, "old").expect("write");
        let mut set = OutputSet::new(Vec::<PathBuf>::new());
        set.add(&a, b"new").expect("staged");
        let err = set
            .add(&dir.path().join("missing/b.txt"), b"x")
            .expect_err("missing folder");
        assert!(matches!(err, OutputError::NoFolder { .. }), "{err}");
        drop(set);
        assert_eq!(fs::read_to_string(&a).expect("read"), "old");
        assert_eq!(fs::read_dir(dir.path()).expect("list").count(), 1);
    }

    #[test]
    fn outputs_equal_to_inputs_or_to_each_other_are_refused() {
        let dir = tempfile::tempdir().expect("temp dir");
        let a = dir.path().join("a.txt");
        fs::write(&a, "in").expect("write");
        let mut set = OutputSet::new([&a]);
        let same = dir.path().join(".").join("a.txt");
        assert!(matches!(
            set.check(&same),
            Err(OutputError::SameAsInput { .. })
        ));
        set.add_in_place(&a, b"rewritten").expect("in place");
        let b = dir.path().join("b.txt");
        set.add(&b, b"b").expect("b");
        assert!(matches!(
            set.add(&dir.path().join("./b.txt"), b"again"),
            Err(OutputError::Duplicate { .. })
        ));
        set.commit().expect("commit");
        assert_eq!(fs::read_to_string(&a).expect("read"), "rewritten");
        assert_eq!(fs::read_to_string(&b).expect("read"), "b");
    }

    #[test]
    fn missing_folder_names_no_temporary_file() {
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path().join("nope/x.stl");
        let err = write_atomically(&out, |f| f.write_all(b"x")).expect_err("missing folder");
        let text = err.to_string();
        assert!(text.contains("does not exist"), "{text}");
        assert!(!text.contains(".conduit-"), "{text}");
    }

    /// A folder that exists but takes no new file (`/proc`): the operating system's reason,
    /// without tempfile's ` at path "<temporary file>"`.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_folder_refusing_files_names_no_temporary_file() {
        let err = write_atomically(Path::new("/proc/conduit-out.stl"), |f| f.write_all(b"x"))
            .expect_err("/proc takes no new file");
        let text = err.to_string();
        assert!(
            !text.contains(".conduit-") && !text.contains("at path"),
            "{text}"
        );
        assert!(text.contains("os error"), "{text}");
    }
}
