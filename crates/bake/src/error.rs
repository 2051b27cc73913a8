//! What can go wrong in a bake, with the file it concerns. The cause is the error's `source`, so
//! a tool printing the chain (`cli::main`) says `error: reading gold.binary: expected 34992012
//! bytes, found 1200`. The path is shown with its control characters escaped
//! ([`fsguard::printable`]): it may come from a manifest.

use std::path::{Path, PathBuf};

type Cause = Box<dyn std::error::Error + Send + Sync>;

/// A bake or stage failure.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An input could not be read or is not what it should be.
    #[error("reading {}", fsguard::printable_path(path))]
    Read {
        path: PathBuf,
        #[source]
        source: Cause,
    },
    /// An input was read but its analysis refused it (e.g. a size the estimator cannot take).
    #[error("analysing {}", fsguard::printable_path(path))]
    Analyse {
        path: PathBuf,
        #[source]
        source: Cause,
    },
    /// An output could not be written.
    #[error("writing {}", fsguard::printable_path(path))]
    Write {
        path: PathBuf,
        #[source]
        source: Cause,
    },
    /// The parameters cannot work together.
    #[error("{0}")]
    Invalid(String),
    /// A stage's algorithm refused its input.
    #[error("{stage}")]
    Stage {
        stage: &'static str,
        #[source]
        source: Cause,
    },
    /// The material's values are no material's (`stage::material_info::unphysical`): validation
    /// found a problem, and nothing was baked from the table.
    #[error(
        "{}: not a physical material, nothing baked: {}",
        fsguard::printable_path(path),
        problems.join("; ")
    )]
    Unphysical { path: PathBuf, problems: Vec<String> },
    /// Another bake holds the folder's lock: one bake at a time per folder.
    #[error(
        "{}: another bake is writing this folder (it holds the folder's lock): wait for it to finish, or bake into \
         another folder",
        fsguard::printable_path(.0)
    )]
    Busy(PathBuf),
    /// A bug: a value the code made does not pass its own checks.
    #[error("internal error: {0}")]
    Internal(String),
}

impl Error {
    pub fn read(path: &Path, source: impl Into<Cause>) -> Error {
        Error::Read { path: path.to_path_buf(), source: source.into() }
    }

    pub fn analyse(path: &Path, source: impl Into<Cause>) -> Error {
        Error::Analyse { path: path.to_path_buf(), source: source.into() }
    }

    pub fn write(path: &Path, source: impl Into<Cause>) -> Error {
        Error::Write { path: path.to_path_buf(), source: source.into() }
    }

    pub fn stage(stage: &'static str, source: impl Into<Cause>) -> Error {
        Error::Stage { stage, source: source.into() }
    }

    /// The message with its causes, `: `-separated, as the tools print it.
    pub fn chain(&self) -> String {
        let mut text = self.to_string();
        let mut cause = std::error::Error::source(self);
        while let Some(c) = cause {
            text.push_str(": ");
            text.push_str(&c.to_string());
            cause = c.source();
        }
        text
    }
}
