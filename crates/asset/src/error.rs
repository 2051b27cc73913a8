//! Why an asset could not be read, split by who is at fault so that callers can choose an exit
//! code or a retry policy without matching on message text.

use crate::container::Header;
use crate::files::hex;

/// Why an asset could not be read or written. Messages are lower case, name the problem and
/// carry no trailing period; the caller adds the file name.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The bytes are not a valid asset: bad magic, truncated, lengths that disagree with the
    /// file size, a section that does not decode.
    #[error("{0}")]
    Invalid(String),
    /// A well-formed file of a version this build cannot read; `what` is `format` for asset
    /// files and `manifest` for bake manifests.
    #[error("unsupported {what} version {found}: this build reads {}", list_versions(readable))]
    UnsupportedVersion { what: &'static str, found: u32, readable: &'static [u32] },
    /// A well-formed file of an asset kind this build does not know.
    #[error("unknown asset kind {code}: this build knows {}", known_kinds())]
    UnknownKind { code: u32 },
    /// A header length above what any reader accepts; checked before anything is allocated.
    #[error("{what} length {found} bytes exceeds the limit of {limit} bytes")]
    LimitExceeded { what: &'static str, found: u64, limit: u64 },
    /// The file is readable but its contents do not hash to the stored checksum. The header
    /// parsed fine and is kept, so a tool can still show it.
    #[error(
        "checksum mismatch: header stores sha256 {}, contents hash to {}",
        hex(&header.checksum),
        hex(computed)
    )]
    ChecksumMismatch { header: Header, computed: [u8; 32] },
    /// The file system failed. The message is the operating system's, lower-cased to match;
    /// it is not reported as a `source` as well, so that a chain printed with `{:#}` does not
    /// say it twice.
    #[error("{}", lower_first(&.0.to_string()))]
    Io(std::io::Error),
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Error {
        Error::Io(e)
    }
}

/// `No such file or directory` reads as `no such file or directory` after a colon.
fn lower_first(message: &str) -> String {
    let mut chars = message.chars();
    match chars.next() {
        Some(first) => first.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}

fn list_versions(readable: &[u32]) -> String {
    match readable {
        [only] => format!("version {only}"),
        versions => {
            let list: Vec<String> = versions.iter().map(u32::to_string).collect();
            format!("versions {}", list.join(", "))
        }
    }
}

fn known_kinds() -> String {
    let list: Vec<String> =
        crate::AssetKind::ALL.iter().map(|kind| format!("{} ({})", kind.code(), kind.name())).collect();
    list.join(", ")
}
