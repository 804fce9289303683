//! Atomic file writes: write to a temporary file in the target's directory, flush it to disk, then rename it over
//! the target. A rename within one directory (one file system) is atomic on POSIX and Windows, so readers see either
//! the old file or the complete new one, and a failure at any step leaves no partial file (the temporary file is
//! removed when it is dropped). O(size of the data).
//!
//! Several files that belong together (a plan and its pictures, the formats of one export) go through
//! [`write_all_atomic`]: every file is first written to its temporary file, and only when all of them are complete are
//! they renamed over their targets, so a failure while writing (a missing or read-only directory, a full disk, a
//! target that is a directory) leaves none of the targets changed.
//!
//! Permissions: the temporary file is created with the mode an ordinary new file would get (`0o666` less the
//! process umask), or with the existing target's mode when it is overwritten, so the rename does not leave an
//! owner-only file behind (the temporary-file default).

use super::IoError;
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically. See the module documentation.
pub fn write_atomic(path: impl AsRef<Path>, bytes: &[u8]) -> Result<(), IoError> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Writes whatever `fill` writes to `path` atomically; if `fill` fails, nothing is left behind and an existing file
/// at `path` is untouched.
pub fn write_atomic_with(
    path: impl AsRef<Path>,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), IoError> {
    let path = path.as_ref();
    persist(staged(path, fill)?, path)
}

/// Writes every `(path, bytes)` of `files` or none of them: all are written to temporary files beside their targets
/// (flushed to disk) before the first is renamed over its target, in the given order (see the module
/// documentation). A failure before the renames leaves every target as it was and no temporary file behind; only a
/// rename itself failing (the file system changed under the program meanwhile) can leave the earlier targets
/// written. The error names the file. O(total size).
pub fn write_all_atomic<'a>(files: impl IntoIterator<Item = (&'a Path, &'a [u8])>) -> Result<(), IoError> {
    let mut staged_files = Vec::new();
    let mut targets = Vec::new();
    for (path, bytes) in files {
        // a target that is a directory would fail only at its rename, after the others were renamed
        if path.is_dir() {
            return Err(IoError::os(path, std::io::Error::other("is a directory")));
        }
        // two outputs to one file: the last would silently replace the first (an SVG in `stack.png`)
        let target = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        if targets.contains(&target) {
            return Err(IoError::os(path, std::io::Error::other("is given for two outputs")));
        }
        targets.push(target);
        staged_files.push((staged(path, |w| w.write_all(bytes))?, path));
    }
    for (tmp, path) in staged_files {
        persist(tmp, path)?;
    }
    Ok(())
}

/// The temporary file beside `path` holding what `fill` wrote, flushed and synced (removed when dropped).
fn staged(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<tempfile::NamedTempFile, IoError> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let err = |e: std::io::Error| IoError::os(path, e);
    let mut builder = tempfile::Builder::new();
    builder.prefix(".stackplan-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // open(2) applies the umask to this mode, exactly as for a file created by `File::create`
        let mode = std::fs::metadata(path).map(|m| m.permissions().mode() & 0o7777).unwrap_or(0o666);
        builder.permissions(std::fs::Permissions::from_mode(mode));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(err)?;
    {
        let mut buffered = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buffered).map_err(err)?;
        buffered.flush().map_err(err)?;
    }
    tmp.as_file().sync_all().map_err(err)?;
    Ok(tmp)
}

/// Renames the staged `tmp` over `path`.
fn persist(tmp: tempfile::NamedTempFile, path: &Path) -> Result<(), IoError> {
    tmp.persist(path).map_err(|e| IoError::os(path, e.error))?;
    tracing::debug!(file = %path.display(), "wrote file atomically");
    Ok(())
}
