//! The one reader of files: capped, regular files only, errors that say which.

use std::io::Read;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

/// The largest text file read by default (graphs, includes, shaders, scenes,
/// scripts): they are written by hand, so a larger one is a mistake.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// What a path that is not a regular file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    Directory,
    Fifo,
    Device,
    Socket,
    Other,
}

impl FileKind {
    pub(crate) fn of(meta: &std::fs::Metadata) -> Self {
        use std::os::unix::fs::FileTypeExt;
        let kind = meta.file_type();
        if kind.is_dir() {
            Self::Directory
        } else if kind.is_fifo() {
            Self::Fifo
        } else if kind.is_char_device() || kind.is_block_device() {
            Self::Device
        } else if kind.is_socket() {
            Self::Socket
        } else {
            Self::Other
        }
    }

    /// The kind in words, as error messages print it ("a FIFO").
    pub fn describe(self) -> &'static str {
        match self {
            Self::Directory => "a directory",
            Self::Fifo => "a FIFO",
            Self::Device => "a device",
            Self::Socket => "a socket",
            Self::Other => "not a regular file",
        }
    }
}

/// Why a file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("{} does not exist", path.display())]
    Missing { path: PathBuf },
    #[error("{} is {}, not a regular file", path.display(), kind.describe())]
    NotRegular { path: PathBuf, kind: FileKind },
    #[error("{} is {size} bytes, over the limit of {limit} bytes", path.display())]
    TooLarge {
        path: PathBuf,
        size: u64,
        limit: u64,
    },
    #[error("{}:{line}: text is not valid UTF-8", path.display())]
    NotUtf8 { path: PathBuf, line: usize },
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl ReadError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Self::Missing { path }
            | Self::NotRegular { path, .. }
            | Self::TooLarge { path, .. }
            | Self::NotUtf8 { path, .. }
            | Self::Io { path, .. } => path,
        }
    }

    /// What is wrong, without the path (for messages that name it already).
    pub fn reason(&self) -> String {
        match self {
            Self::Missing { .. } => "no such file".to_string(),
            Self::NotRegular { kind, .. } => {
                format!("it is {}, not a regular file", kind.describe())
            }
            Self::TooLarge { size, limit, .. } => {
                format!("it is {size} bytes, over the limit of {limit} bytes")
            }
            Self::NotUtf8 { line, .. } => format!("line {line} is not valid UTF-8"),
            Self::Io { source, .. } => source.to_string(),
        }
    }

    /// The error as `std::io::Error` carrying [`ReadError::reason`], for APIs
    /// that speak it (a missing file keeps `NotFound`).
    pub fn into_io(self) -> std::io::Error {
        let kind = match &self {
            Self::Missing { .. } => std::io::ErrorKind::NotFound,
            Self::Io { source, .. } => source.kind(),
            _ => std::io::ErrorKind::InvalidData,
        };
        std::io::Error::new(kind, self.reason())
    }
}

/// Opens a regular file for reading without reading it (for decoders that
/// read only a header), refusing directories, FIFOs, devices and sockets as
/// [`read_capped`] does, and checking what was opened.
pub fn open_regular(path: &Path) -> Result<std::fs::File, ReadError> {
    let io_error = |source: std::io::Error| {
        if source.kind() == std::io::ErrorKind::NotFound {
            ReadError::Missing {
                path: path.to_path_buf(),
            }
        } else {
            ReadError::Io {
                path: path.to_path_buf(),
                source,
            }
        }
    };
    let meta = std::fs::metadata(path).map_err(io_error)?;
    if !meta.is_file() {
        return Err(ReadError::NotRegular {
            path: path.to_path_buf(),
            kind: FileKind::of(&meta),
        });
    }
    // Non-blocking, so a path swapped for a FIFO after the check above fails
    // the check below instead of blocking in open (regular files ignore it).
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(io_error)?;
    let opened = file.metadata().map_err(io_error)?;
    if !opened.is_file() {
        return Err(ReadError::NotRegular {
            path: path.to_path_buf(),
            kind: FileKind::of(&opened),
        });
    }
    Ok(file)
}

/// Reads a whole regular file, refusing directories, FIFOs, devices and
/// sockets (a link is followed to what it names), and files over `limit`
/// bytes; the limit caps the bytes actually read, since a file can grow (or,
/// under `/proc`, report no size) after its metadata was read.
pub fn read_capped(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    let file = open_regular(path)?;
    let too_large = |size| ReadError::TooLarge {
        path: path.to_path_buf(),
        size,
        limit,
    };
    let len = file
        .metadata()
        .map_err(|source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        })?
        .len();
    if len > limit {
        return Err(too_large(len));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Reads a text file with [`read_capped`], reporting the line of the first
/// byte that is not UTF-8. A leading UTF-8 byte-order mark (some Windows
/// editors write one) is dropped. The text is remembered in
/// [`crate::sources`] for error printers.
pub fn read_text(path: &Path, limit: u64) -> Result<String, ReadError> {
    let mut bytes = read_capped(path, limit)?;
    if bytes.starts_with(UTF8_BOM) {
        bytes.drain(..UTF8_BOM.len());
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..valid]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        ReadError::NotUtf8 {
            path: path.to_path_buf(),
            line,
        }
    })?;
    crate::sources::remember(path, &text);
    Ok(text)
}

/// The UTF-8 encoding of U+FEFF, the byte-order mark.
const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_fifos_and_folders_are_refused_without_reading() {
        let dir = crate::test_dir("kinds");
        let fifo = dir.join("fifo");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo");
        assert!(made.success());
        for (path, kind) in [
            (Path::new("/dev/zero"), FileKind::Device),
            (fifo.as_path(), FileKind::Fifo),
            (dir.as_path(), FileKind::Directory),
        ] {
            match read_capped(path, 1 << 20) {
                Err(ReadError::NotRegular { kind: k, .. }) => assert_eq!(k, kind, "{path:?}"),
                other => panic!("{path:?}: {other:?}"),
            }
        }
        let link = dir.join("link");
        std::os::unix::fs::symlink("/dev/zero", &link).expect("symlink");
        let error = read_capped(&link, 1 << 20).expect_err("a link to a device");
        assert_eq!(
            error.to_string(),
            format!("{} is a device, not a regular file", link.display())
        );
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn the_limit_caps_what_is_read_even_when_the_size_is_not_known() {
        // /proc files report size 0 and may be longer than any limit.
        match read_capped(Path::new("/proc/self/maps"), 4) {
            Err(ReadError::TooLarge {
                size: 5, limit: 4, ..
            }) => {}
            other => panic!("{other:?}"),
        }
        let dir = crate::test_dir("limit");
        let file = dir.join("big.txt");
        std::fs::write(&file, "0123456789").expect("write");
        let error = read_capped(&file, 9).expect_err("over the limit");
        assert_eq!(
            error.to_string(),
            format!("{} is 10 bytes, over the limit of 9 bytes", file.display())
        );
        assert_eq!(read_capped(&file, 10).expect("at the limit").len(), 10);
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn text_reports_the_line_of_bad_utf8_and_drops_a_bom() {
        let dir = crate::test_dir("text");
        let file = dir.join("t.txt");
        std::fs::write(&file, b"\xEF\xBB\xBFa\nb\n\xFF\n").expect("write");
        match read_text(&file, 100) {
            Err(ReadError::NotUtf8 { line: 3, .. }) => {}
            other => panic!("{other:?}"),
        }
        std::fs::write(&file, b"\xEF\xBB\xBFa\nb\n").expect("write");
        assert_eq!(read_text(&file, 100).expect("text"), "a\nb\n");
        assert_eq!(
            crate::sources::text_of(&file).as_deref(),
            Some("a\nb\n"),
            "remembered for printers"
        );
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
