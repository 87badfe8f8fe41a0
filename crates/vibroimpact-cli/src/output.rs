//! Atomic output: every file the CLI writes is first written to a temporary
//! sibling and then renamed, so an interrupted or failed run never leaves a
//! partial file behind.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files and folders being written (removed by a hard stop).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A temporary file or folder registered while it is written: a second
/// Ctrl-C ([`crate::interrupt`]) removes it before the process quits, so no
/// `*.tmp<PID>` is left behind. Dropping the guard unregisters it.
#[derive(Debug)]
pub struct Pending(PathBuf);

impl Pending {
    /// Registers `path`.
    pub fn new(path: &Path) -> Self {
        if let Ok(mut list) = PENDING.lock() {
            list.push(path.to_path_buf());
        }
        Self(path.to_path_buf())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if let Ok(mut list) = PENDING.lock() {
            if let Some(i) = list.iter().rposition(|p| *p == self.0) {
                list.swap_remove(i);
            }
        }
    }
}

/// Removes every registered temporary file and folder (before a hard stop).
pub fn remove_pending() {
    if let Ok(list) = PENDING.lock() {
        for p in list.iter() {
            let _ = if p.is_dir() {
                fs::remove_dir_all(p)
            } else {
                fs::remove_file(p)
            };
        }
    }
}

/// Error while writing an output file; names the file.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {path}: {source}")]
pub struct OutputError {
    /// The file that could not be written.
    pub path: PathBuf,
    /// The underlying I/O error.
    #[source]
    pub source: std::io::Error,
}

/// Temporary sibling of `path` used while writing it.
pub fn temp_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".tmp{}", std::process::id()));
    path.with_file_name(name)
}

/// Writes `bytes` to `path` atomically (write a temporary sibling, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let err = |source| OutputError {
        path: path.to_path_buf(),
        source,
    };
    let tmp = temp_path(path);
    let _pending = Pending::new(&tmp);
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(err)
}

/// Renames a finished temporary file onto `path` (for writers that need a path,
/// such as the PNG encoder). Removes the temporary file on failure.
pub fn commit_temp(tmp: &Path, path: &Path) -> Result<(), OutputError> {
    fs::rename(tmp, path).map_err(|source| {
        let _ = fs::remove_file(tmp);
        OutputError {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// Creates the directory `dir` (and parents) if missing; a path that is
/// there but not a folder (`--out /dev/null`, a file) is named as such,
/// not as the system's "File exists".
pub fn ensure_dir(dir: &Path) -> Result<(), OutputError> {
    if dir.exists() && !dir.is_dir() {
        return Err(OutputError {
            path: dir.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "not a folder: --out names the folder the command writes its files into",
            ),
        });
    }
    fs::create_dir_all(dir).map_err(|source| OutputError {
        path: dir.to_path_buf(),
        source,
    })
}
