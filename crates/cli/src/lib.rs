//! What the `main` of every tool shares, so that they all behave alike in a pipeline: exit 0 when
//! all is well, 1 when a validation found a problem (the tool returns that code itself), 2 on an
//! error, printed as one line `error: context: problem`; and printing to stdout that ends the
//! process quietly when the reader goes away (`merl-info x.binary --json | head`) instead of
//! panicking as `println!` does.
//!
//! It also holds the one way tools print what they did ([`finish`]: a report for people, or with
//! `--json` one JSON object on stdout and the human lines on stderr) and the one progress bar
//! ([`Progress`]). The error line and the lines of [`finish`] are printed through
//! [`printable`] (`fsguard`'s): a name a file gave (a manifest's path, a material's
//! `source_path`) can neither break them into lines nor send escape sequences to a terminal.
//!
//! Only tools depend on this crate.

use std::fmt;
use std::io::{ErrorKind, IsTerminal, Write};
use std::process::ExitCode;
use std::time::{Duration, Instant};

pub use fsguard::{printable, printable_path};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Runs a tool's `run` and turns its result into the process exit status.
pub fn main(run: impl FnOnce() -> anyhow::Result<ExitCode>) -> ExitCode {
    match run() {
        Ok(code) => code,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let chain: Vec<String> = e.chain().map(|c| lower_case_start(&c.to_string())).collect();
            eprintln!("error: {}", printable(&chain.join(": ")));
            ExitCode::from(2)
        }
    }
}

/// Parses the command line into a tool's arguments. `--help` and `--version` print as clap does
/// and exit 0; a usage error becomes an error of one line (clap's own message spans several, with
/// the usage after it), which [`main`] prints with exit status 2, as for any other error.
pub fn args<T: clap::Parser>() -> anyhow::Result<T> {
    T::try_parse().map_err(|e| {
        if !e.use_stderr() {
            e.exit()
        }
        anyhow::anyhow!("{}", usage_error(&e, T::command().get_name()))
    })
}

/// A clap error as one line: its message and tips, without the usage that clap prints after them,
/// and where to read more.
fn usage_error(e: &clap::Error, tool: &str) -> String {
    let rendered = e.render().to_string();
    let message = rendered.split("\nUsage:").next().unwrap_or_default();
    // Paragraphs (a message, a tip) apart with "; ", the lines of a list after a colon with ", ";
    // clap's pointer to `--help` replaced by the tool's.
    let mut parts = Vec::new();
    for paragraph in message.split("\n\n") {
        let mut lines = paragraph.lines().map(str::trim).filter(|l| !l.is_empty());
        let Some(first) = lines.next().filter(|l| !l.starts_with("For more information")) else { continue };
        let first = first.strip_prefix("error: ").unwrap_or(first);
        let rest: Vec<&str> = lines.collect();
        parts.push(if rest.is_empty() {
            first.to_string()
        } else if first.ends_with(':') {
            format!("{first} {}", rest.join(", "))
        } else {
            format!("{first}; {}", rest.join("; "))
        });
    }
    format!("{}; see {tool} --help", parts.join("; "))
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

/// Runs `f` with the process's standard error sent to a temporary file, then prints what was
/// written there except the lines `spurious` accepts, in order: for libraries that print a
/// message of their own on a path that succeeds. (Mesa's Vulkan device-selection layer asks for a
/// Wayland display while adapters are enumerated, and libwayland prints `error: XDG_RUNTIME_DIR is
/// invalid or not set in the environment.` when there is none: a headless render needs none, and
/// a script that looks for `error:` would take it for a failure.) Standard error is restored even
/// if `f` panics; where it cannot be redirected, `f` runs as it is.
pub fn without_stderr_lines<T>(spurious: impl Fn(&str) -> bool, f: impl FnOnce() -> T) -> T {
    use std::io::{Read, Seek};
    /// Puts the original standard error back when dropped.
    struct Restore(std::os::fd::OwnedFd);
    impl Drop for Restore {
        fn drop(&mut self) {
            let _ = std::io::stderr().flush();
            let _ = rustix::stdio::dup2_stderr(&self.0);
        }
    }
    let redirected = tempfile::tempfile().and_then(|capture| {
        let saved = rustix::io::dup(std::io::stderr())?;
        let _ = std::io::stderr().flush();
        rustix::stdio::dup2_stderr(&capture)?;
        Ok((capture, Restore(saved)))
    });
    let Ok((mut capture, restore)) = redirected else { return f() };
    let result = f();
    drop(restore);
    let mut text = String::new();
    if capture.rewind().and_then(|()| capture.read_to_string(&mut text)).is_ok() {
        for line in text.lines().filter(|line| !spurious(line)) {
            eprintln!("{line}");
        }
    }
    result
}

/// libwayland's complaint that there is no Wayland session (see [`without_stderr_lines`]).
pub fn is_wayland_session_warning(line: &str) -> bool {
    line.starts_with("error: XDG_RUNTIME_DIR") && line.contains("not set in the environment")
}

/// Parses a `WIDTHxHEIGHT` argument (`x` or `X`), as clap's `value_parser` wants it. Sizes are
/// checked by whoever uses them; this only reads the two numbers.
pub fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let parse = |s: &str| s.trim().parse::<usize>().map_err(|e| format!("{s:?}: {e}"));
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got {text:?}"))?;
    Ok((parse(w)?, parse(h)?))
}

/// Parses a count option (samples, sizes, components), as clap's `value_parser` wants it: a
/// whole number from 1 up. Tools set `allow_negative_numbers` on their commands, so `-1`
/// reaches this parser and the message says what the option accepts.
pub fn parse_count(text: &str) -> Result<usize, String> {
    parse_whole(text, 1)
}

/// Parses a whole number from `min` up (as [`parse_count`] does from 1).
pub fn parse_whole(text: &str, min: usize) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if n >= min => Ok(n),
        _ => Err(format!("expected a whole number from {min} up")),
    }
}

/// [`parse_count`] for options held in a `u32`: a whole number from 1 to 4294967295.
pub fn parse_count_u32(text: &str) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err("expected a whole number from 1 to 4294967295".to_string()),
    }
}

/// Parses a finite number within `min..=max` (an option where NaN or an infinity makes no sense);
/// the error gives the range.
pub fn parse_finite(text: &str, min: f64, max: f64) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && (min..=max).contains(&v) => Ok(v),
        _ => Err(format!("expected a number from {min} to {max}")),
    }
}

/// Parses a memory size (`--max-memory`): a whole number of bytes, or of KiB, MiB or GiB with the
/// suffix `K`, `M`, `G` (or `KiB`, `MiB`, `GiB`; any case).
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let lower = text.trim().to_ascii_lowercase();
    let (number, shift) = [("gib", 30), ("g", 30), ("mib", 20), ("m", 20), ("kib", 10), ("k", 10)]
        .iter()
        .find_map(|&(suffix, shift)| lower.strip_suffix(suffix).map(|n| (n.trim(), shift)))
        .unwrap_or((lower.as_str(), 0));
    let bad = || format!("expected a size such as 4G, 512M or 1048576 (bytes), found {text:?}");
    let value: u64 = number.parse().map_err(|_| bad())?;
    value.checked_mul(1 << shift).filter(|&v| v > 0).ok_or_else(bad)
}

/// Prints a tool's outcome the way every tool does and returns its exit status. With `json`,
/// stdout gets exactly `value` (one JSON object, which lists the files written) and the report
/// goes to stderr; without, the report and the problems go to stdout. Either way the files written
/// are listed on stderr. Exit 1 when there are problems, else 0.
pub fn finish(
    json: bool,
    value: &serde_json::Value,
    report: &[String],
    problems: &[String],
    written: &[String],
) -> ExitCode {
    let found_problems = !problems.is_empty();
    let (report, problems) = (report.iter().map(|l| printable(l)), problems.iter().map(|p| printable(p)));
    if json {
        for line in report {
            eprintln!("{line}");
        }
        for problem in problems {
            eprintln!("problem: {problem}");
        }
        write_line(format_args!("{}", serde_json::to_string_pretty(value).expect("json values serialize")));
    } else {
        for line in report {
            write_line(format_args!("{line}"));
        }
        for problem in problems {
            write_line(format_args!("problem: {problem}"));
        }
    }
    if !written.is_empty() {
        eprintln!("wrote {}", printable(&written.join(", ")));
    }
    if found_problems { ExitCode::from(1) } else { ExitCode::SUCCESS }
}

/// The progress bar of a long job, on stderr. It appears only on a terminal, only once the job has
/// run for a second (quick runs stay quiet), never with `quiet`; it shows the current step's name
/// and, when the step reports its work, how far it is.
#[derive(Debug)]
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
    enabled: bool,
    shown: std::sync::atomic::AtomicBool,
}

impl Progress {
    pub fn new(quiet: bool) -> Progress {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{msg} [{bar:30}] {percent:>3}% {elapsed}").expect("a valid template"),
        );
        let enabled = !quiet && std::io::stderr().is_terminal();
        Progress { bar, start: Instant::now(), enabled, shown: std::sync::atomic::AtomicBool::new(false) }
    }

    /// A new step begins: `message` says which (e.g. "2/5 bandwidth atlas").
    pub fn step(&self, message: String) {
        self.bar.set_message(message);
        self.bar.set_length(1);
        self.bar.set_position(0);
        self.show_if_slow();
    }

    /// Within the current step, `done` of `total` units are done.
    pub fn work(&self, done: u64, total: u64) {
        self.bar.set_length(total.max(1));
        self.bar.set_position(done.min(total));
        self.show_if_slow();
    }

    fn show_if_slow(&self) {
        if self.enabled
            && self.start.elapsed() > Duration::from_secs(1)
            && !self.shown.swap(true, std::sync::atomic::Ordering::Relaxed)
        {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.bar.enable_steady_tick(Duration::from_millis(100));
        }
    }

    /// Removes the bar (call before printing the report).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::{is_wayland_session_warning, lower_case_start, parse_bytes, parse_count, parse_size, usage_error};

    #[test]
    fn only_the_wayland_session_warning_is_spurious() {
        assert!(is_wayland_session_warning("error: XDG_RUNTIME_DIR is invalid or not set in the environment."));
        assert!(is_wayland_session_warning("error: XDG_RUNTIME_DIR not set in the environment."));
        assert!(!is_wayland_session_warning("error: reading x: no such file or directory"));
        assert!(!is_wayland_session_warning("warning: XDG_RUNTIME_DIR is invalid or not set in the environment."));
    }

    /// clap's messages of several lines (a list of missing arguments, a tip) become one, without
    /// the usage; what clap says stays.
    #[test]
    fn usage_errors_are_one_line() {
        use clap::{Arg, ArgAction, Command};
        let command = || {
            Command::new("tool")
                .arg(Arg::new("input").required(true))
                .arg(Arg::new("out").long("out").required(true))
                .arg(Arg::new("quiet").long("quiet").action(ArgAction::SetTrue))
                .arg(Arg::new("n").long("n").value_parser(clap::value_parser!(u32)))
        };
        let cases: [(&[&str], &str); 5] = [
            (
                &["tool", "in", "--out", "x", "--n", "x"],
                "invalid value 'x' for '--n <n>': invalid digit found in string; see tool --help",
            ),
            (&["tool"], "the following required arguments were not provided: --out <out>, <input>; see tool --help"),
            (&["tool", "in"], "the following required arguments were not provided: --out <out>; see tool --help"),
            (
                &["tool", "in", "--out", "x", "--quiet=3"],
                "unexpected value '3' for '--quiet' found; no more were expected",
            ),
            (
                &["tool", "--bake", "x"],
                "unexpected argument '--bake' found; tip: to pass '--bake' as a value, use '-- --bake'",
            ),
        ];
        for (argv, expected) in cases {
            let e = command().try_get_matches_from(argv).expect_err("a usage error");
            let line = usage_error(&e, "tool");
            assert!(line.starts_with(expected), "{argv:?}: {line}");
            let one = !line.contains('\n') && !line.contains("Usage") && !line.contains("For more information");
            assert!(one && line.ends_with("; see tool --help"), "{line}");
        }
    }

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("64x32"), Ok((64, 32)));
        assert_eq!(parse_size("64X32"), Ok((64, 32)));
        assert_eq!(parse_size(" 8 x 4 "), Ok((8, 4)));
        assert!(parse_size("64").is_err());
        assert!(parse_size("ax32").is_err());
        assert!(parse_size("-1x2").is_err());
    }

    #[test]
    fn counts_and_memory_sizes_parse() {
        assert_eq!(super::parse_count_u32("4294967295"), Ok(u32::MAX));
        for bad in ["0", "-1", "4294967296", "nan"] {
            assert!(super::parse_count_u32(bad).is_err(), "{bad}");
        }
        assert_eq!(super::parse_finite("-2.5", -64.0, 64.0), Ok(-2.5));
        for bad in ["nan", "NaN", "inf", "-inf", "65", "x", "1e400"] {
            assert_eq!(super::parse_finite(bad, -64.0, 64.0), Err("expected a number from -64 to 64".to_string()));
        }
        assert_eq!(parse_count("3"), Ok(3));
        for bad in ["0", "-1", "2.5", "x", ""] {
            assert!(parse_count(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("4gib"), Ok(4 << 30));
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("64 KiB"), Ok(64 << 10));
        assert_eq!(parse_bytes("1048576"), Ok(1 << 20));
        for bad in ["0", "-1G", "1.5G", "4T", "G", "99999999999G"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }

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
