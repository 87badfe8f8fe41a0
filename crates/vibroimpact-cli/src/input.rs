//! Reading input files (model files, accelerograms, measurements, guesses)
//! with limits: regular files only — a FIFO would block forever and a
//! device such as `/dev/zero` never ends — of at most [`MAX_INPUT_BYTES`].

use std::io::{self, Read};
use std::path::Path;

pub use vibroimpact::model::file::MAX_INPUT_BYTES;

/// The text of the regular file `path`, refused (with the reason) if it is
/// a directory, FIFO or device, or larger than [`MAX_INPUT_BYTES`].
pub fn read_text(path: &Path) -> io::Result<String> {
    // `metadata` does not open the file: a FIFO is refused without blocking.
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a regular file (a directory, FIFO or device cannot be read as input)",
        ));
    }
    let too_large = |len: u64| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{len} bytes, more than the input limit of {MAX_INPUT_BYTES} bytes"),
        )
    };
    if meta.len() > MAX_INPUT_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(MAX_INPUT_BYTES + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > MAX_INPUT_BYTES {
        return Err(too_large(text.len() as u64));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_is_not_a_regular_file() {
        let dir = std::env::temp_dir();
        let e = read_text(&dir).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        #[cfg(unix)]
        {
            let e = read_text(Path::new("/dev/zero")).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
            let fifo = dir.join(format!("vi-fifo-{}", std::process::id()));
            let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
            // SAFETY: a valid NUL-terminated path.
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
            let e = read_text(&fifo).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
            std::fs::remove_file(&fifo).unwrap();
        }
        let file = dir.join(format!("vi-input-{}.txt", std::process::id()));
        std::fs::write(&file, "a = 1\n").unwrap();
        assert_eq!(read_text(&file).unwrap(), "a = 1\n");
        std::fs::remove_file(&file).unwrap();
    }
}
