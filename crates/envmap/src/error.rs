/// Why a map could not be read or an output written, split by who is at fault. Messages are lower
/// case and name the problem; the caller adds the file name (`error: reading FILE: problem`).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The bytes (or the values a caller passed in) are not a valid map: a short read, a damaged
    /// header, NaN, negative radiance, a shape that is not 2:1, ...
    #[error("{0}")]
    Invalid(String),
    /// Valid data in a form this crate does not read: another file format, a rotated Radiance
    /// file, XYZ pixels, deep or subsampled EXR data, integer channels, no R, G, B or Y channels.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The map is larger than [`crate::Limits`] allow; checked from the header, before decoding.
    #[error("limit exceeded: {0}")]
    LimitExceeded(String),
    /// The file system failed (not found, permission, ...). A file that ends early is `Invalid`.
    #[error(transparent)]
    Io(std::io::Error),
}

impl From<std::io::Error> for Error {
    fn from(error: std::io::Error) -> Self {
        if error.kind() == std::io::ErrorKind::UnexpectedEof {
            Error::Invalid("truncated: the file ends early".into())
        } else {
            Error::Io(error)
        }
    }
}

impl From<exr::error::Error> for Error {
    fn from(error: exr::error::Error) -> Self {
        use exr::error::Error as E;
        match error {
            // `exr` turns every unexpected end of file into this message.
            E::Invalid(message) if message == "reference to missing bytes" => {
                Error::Invalid("openexr: truncated: the file ends early".into())
            }
            E::Invalid(message) => Error::Invalid(format!("openexr: {message}")),
            E::NotSupported(message) => Error::Unsupported(format!("openexr: {message}")),
            E::Io(error) => error.into(),
            E::Aborted => Error::Io(std::io::Error::other("openexr: aborted")),
        }
    }
}

impl Error {
    /// An error of the `image` crate while reading or writing `format` ("radiance hdr", "png").
    pub(crate) fn from_image(format: &str, error: image::ImageError) -> Error {
        use image::ImageError as E;
        use image::error::UnsupportedErrorKind;
        match error {
            E::IoError(error) if error.kind() == std::io::ErrorKind::UnexpectedEof => {
                Error::Invalid(format!("{format}: truncated: the file ends early"))
            }
            E::IoError(error) => Error::Io(error),
            E::Unsupported(error) => Error::Unsupported(match error.kind() {
                UnsupportedErrorKind::GenericFeature(feature) => format!("{format}: {}", lower_first(&feature)),
                UnsupportedErrorKind::Format(image::error::ImageFormatHint::Name(name)) => {
                    format!("{format}: pixel format {name}")
                }
                _ => format!("{format}: {}", lower_first(&error.to_string())),
            }),
            E::Limits(error) => Error::LimitExceeded(format!("{format}: {}", lower_first(&error.to_string()))),
            // The decoder's own message is in the source; the outer one only repeats the format.
            E::Decoding(error) => {
                let message = std::error::Error::source(&error).map_or_else(|| error.to_string(), |s| s.to_string());
                Error::Invalid(format!("{format}: {}", lower_first(&message)))
            }
            E::Encoding(_) | E::Parameter(_) => {
                Error::Invalid(format!("{format}: {}", lower_first(&error.to_string())))
            }
        }
    }
}

/// The `image` crate's messages start with a capital letter; ours never do. An acronym ("EOF in
/// header") stays as it is.
fn lower_first(message: &str) -> String {
    let mut chars = message.chars();
    match (chars.next(), chars.next()) {
        (Some(_), Some(second)) if second.is_uppercase() => message.to_string(),
        (Some(first), _) => first.to_lowercase().chain(message[first.len_utf8()..].chars()).collect(),
        (None, _) => String::new(),
    }
}
