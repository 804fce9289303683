//! Atomic file writes: write to a temporary file in the target's directory, flush it to disk, then rename it over
//! the target. A rename within one directory (one file system) is atomic on POSIX and Windows, so readers see either
//! the old file or the complete new one, and a failure at any step leaves no partial file (the temporary file is
//! removed when it is dropped). O(size of the data).
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
    tmp.persist(path).map_err(|e| err(e.error))?;
    tracing::debug!(file = %path.display(), "wrote file atomically");
    Ok(())
}
