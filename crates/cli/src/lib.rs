//! What the `main` of every tool shares, so that they all behave alike in a pipeline: exit 0 when
//! all is well, 1 when a validation found a problem (the tool returns that code itself), 2 on an
//! error, printed as one line `error: context: problem`; and printing to stdout that ends the
//! process quietly when the reader goes away (`merl-info x.binary --json | head`) instead of
//! panicking as `println!` does.
//!
//! Only tools depend on this crate.

use std::fmt;
use std::io::{ErrorKind, Write};
use std::process::ExitCode;

/// Runs a tool's `run` and turns its result into the process exit status.
pub fn main(run: impl FnOnce() -> anyhow::Result<ExitCode>) -> ExitCode {
    match run() {
        Ok(code) => code,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let chain: Vec<String> = e.chain().map(|c| lower_case_start(&c.to_string())).collect();
            eprintln!("error: {}", chain.join(": "));
            ExitCode::from(2)
        }
    }
}

/// Messages start in lower case, whoever wrote them (the operating system writes "No such file
/// or directory"); a first word that is not plain capitalized ("NaN", "EXR") is left alone.
fn lower_case_start(message: &str) -> String {
    let first_word = message.split(|c: char| !c.is_alphanumeric()).next().unwrap_or("");
    let mut chars = first_word.chars();
    match chars.next() {
        Some(c) if c.is_uppercase() && chars.all(|c| c.is_lowercase()) => {
            c.to_lowercase().chain(message[c.len_utf8()..].chars()).collect()
        }
        _ => message.to_string(),
    }
}

/// A write to stdout failed because its reader went away: not an error of the tool.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == ErrorKind::BrokenPipe))
}

/// Writes one line to stdout; what [`outln!`] expands to. A closed pipe ends the process with
/// status 0 (the reader has what it wanted); any other write error with status 2.
pub fn write_line(args: fmt::Arguments<'_>) {
    let mut out = std::io::stdout().lock();
    if let Err(e) = writeln!(out, "{args}") {
        if e.kind() == ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: writing to stdout: {e}");
        std::process::exit(2);
    }
}

/// `println!` for tools: see [`write_line`].
#[macro_export]
macro_rules! outln {
    () => { $crate::write_line(format_args!("")) };
    ($($arg:tt)*) => { $crate::write_line(format_args!($($arg)*)) };
}

#[cfg(test)]
mod tests {
    use super::lower_case_start;

    #[test]
    fn only_plain_capitalized_first_words_are_lowered() {
        assert_eq!(
            lower_case_start("No such file or directory (os error 2)"),
            "no such file or directory (os error 2)"
        );
        assert_eq!(lower_case_start("NaN value in the red channel"), "NaN value in the red channel");
        assert_eq!(lower_case_start("EXR: bad header"), "EXR: bad header");
        assert_eq!(lower_case_start("truncated header"), "truncated header");
        assert_eq!(lower_case_start(""), "");
    }
}
