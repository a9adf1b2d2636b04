//! The one writer through which every output file is written: [`write_atomically`].

use std::fmt;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The step of [`write_atomically`] that failed.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum WriteStep {
    /// Creating the temporary file next to the target.
    CreateTemp,
    /// Opening a target that is not a regular file (a device, a pipe) to write in place.
    Open,
    /// Writing the bytes out (flushing the buffer).
    Write,
    /// Syncing the temporary file to disk.
    Sync,
    /// Renaming the temporary file over the target.
    Rename,
}

impl fmt::Display for WriteStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            WriteStep::CreateTemp => "creating a temporary file beside it",
            WriteStep::Open => "opening",
            WriteStep::Write => "writing",
            WriteStep::Sync => "syncing to disk",
            WriteStep::Rename => "renaming the temporary file over it",
        })
    }
}

/// A failure of [`write_atomically`] itself, naming the file; the old file, if any, is left as it
/// was.
#[derive(Debug, thiserror::Error)]
#[error("{}: {step}: {error}", path.display())]
pub struct WriteError {
    /// The file being written.
    pub path: PathBuf,
    /// The step that failed.
    pub step: WriteStep,
    /// The operating system's error.
    pub error: io::Error,
}

/// An [`io::Error`] of the same kind whose message is the [`WriteError`]'s (naming the file).
impl From<WriteError> for io::Error {
    fn from(e: WriteError) -> io::Error {
        io::Error::new(e.error.kind(), e)
    }
}

/// Writes the file at `path` through `write`, which gets a buffered writer: the file is either
/// wholly replaced by what `write` wrote or left as it was.
///
/// `write` writes into a temporary file `.NAME.tmpXXXXXX` in the target's own folder; that file
/// is flushed and synced to disk, then renamed over the target, and on Unix the folder is synced
/// (best effort). If `write` or the writer fails, the temporary file is removed and the old file
/// is untouched; if the process dies mid-write, the old file is untouched and the temporary file
/// may be left behind.
///
/// The new file gets the old file's permissions, or those [`std::fs::File::create`] would give.
/// A symbolic link is followed: the file it points to is replaced. A device or a pipe cannot be
/// replaced and is written in place.
///
/// Returns what `write` returned. An error of `write` is returned as it is; the writer's own
/// failures are [`WriteError`]s, converted into `E`.
pub fn write_atomically<T, E: From<WriteError>>(
    path: impl AsRef<Path>,
    write: impl FnOnce(&mut dyn Write) -> Result<T, E>,
) -> Result<T, E> {
    let path = path.as_ref();
    let fail = |step, error| WriteError { path: path.to_owned(), step, error };
    let target = match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => {
            std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned())
        }
        _ => path.to_owned(),
    };
    let old = std::fs::metadata(&target).ok();
    if old.as_ref().is_some_and(|m| !m.is_file() && !m.is_dir()) {
        let file = std::fs::File::create(&target).map_err(|e| fail(WriteStep::Open, e))?;
        let mut out = BufWriter::new(file);
        let value = write(&mut out)?;
        out.flush().map_err(|e| fail(WriteStep::Write, e))?;
        return Ok(value);
    }

    let name = target.file_name().ok_or_else(|| {
        fail(WriteStep::CreateTemp, io::Error::new(io::ErrorKind::InvalidInput, "not a file name"))
    })?;
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(name);
    prefix.push(".tmp");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        // What `File::create` asks for; the umask applies.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let temp = builder.tempfile_in(dir).map_err(|e| fail(WriteStep::CreateTemp, e))?;

    let mut out = BufWriter::new(temp.as_file());
    let value = match write(&mut out) {
        Ok(value) => value,
        Err(e) => {
            drop(out);
            let _ = temp.close();
            return Err(e);
        }
    };
    if let Err(e) = out.flush() {
        drop(out);
        let _ = temp.close();
        return Err(fail(WriteStep::Write, e).into());
    }
    drop(out);
    if let Err(e) = temp.as_file().sync_all() {
        let _ = temp.close();
        return Err(fail(WriteStep::Sync, e).into());
    }
    if let Some(old) = &old {
        // Best effort: the new file keeps the old one's mode.
        let _ = temp.as_file().set_permissions(old.permissions());
    }
    // On failure the returned temporary file is dropped, which removes it.
    temp.persist(&target).map_err(|e| fail(WriteStep::Rename, e.error))?;
    #[cfg(unix)]
    if let Ok(folder) = std::fs::File::open(dir) {
        // Best effort: makes the rename itself durable.
        let _ = folder.sync_all();
    }
    Ok(value)
}

/// [`write_atomically`] of `bytes`: the file at `path` holds exactly `bytes`, or is left as it
/// was; every error names the file.
pub fn write_bytes_atomically(
    path: impl AsRef<Path>,
    bytes: impl AsRef<[u8]>,
) -> Result<(), WriteError> {
    let path = path.as_ref();
    write_atomically(path, |w| {
        w.write_all(bytes.as_ref()).map_err(|error| WriteError {
            path: path.to_owned(),
            step: WriteStep::Write,
            error,
        })
    })
}
