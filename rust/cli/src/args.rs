//! The command line's own failure modes: argument errors in one line, and writing to a
//! stdout whose reader may have gone away.

use std::io::Write;
use std::process::ExitCode;

use clap::error::ErrorKind;

/// Largest `--threads`, the same bound as the scene's `threads` setting.
pub const MAX_THREADS: i64 = penumbra::scene::settings::MAX_THREADS as i64;

/// Reports a clap error: `--help` and `--version` print as usual (exit 0); every other error
/// is one line, `penumbra: error: … (see --help)`, exit 2, instead of clap's usage block —
/// a script reading stderr gets the reason, and a person knows where to look for the rest.
pub fn report(e: clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            ExitCode::SUCCESS
        }
        _ => {
            eprintln!("penumbra: {}", one_line(&e));
            ExitCode::from(2)
        }
    }
}

/// The first line of clap's message (which already starts with `error: `), with clap's
/// usage and tips dropped; a missing subcommand, which clap answers with the whole help,
/// gets a sentence of its own.
pub fn one_line(e: &clap::Error) -> String {
    if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
        || e.kind() == ErrorKind::MissingSubcommand
    {
        return "error: a command is required: bake, validate or scene (see --help)".into();
    }
    let text = e.to_string();
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("error: invalid arguments");
    let first = first.trim_end_matches('.');
    // Clap puts the missing arguments on the lines after "the following required arguments
    // were not provided:"; fold them into the line.
    if e.kind() == ErrorKind::MissingRequiredArgument {
        let missing: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.trim_start().starts_with("error:"))
            .skip(1)
            .map(str::trim)
            .take_while(|l| !l.is_empty() && !l.starts_with("Usage:"))
            .collect();
        if !missing.is_empty() {
            return format!("{first} {} (see --help)", missing.join(" "));
        }
    }
    format!("{first} (see --help)")
}

/// Writes the bake JSON to stdout and flushes it: a closed pipe comes back as the error
/// (`BrokenPipe`) instead of `println!`'s panic.
pub fn write_stdout(text: &str) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.write_all(b"\n")?;
    out.flush()
}

/// `--max-memory`: bytes, or a number with a K, M, G or T suffix (powers of 1024, an
/// optional "iB" or "B" after it): `8G`, `512MiB`, `1.5G`.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (num, shift) = match t.chars().last().map(|c| c.to_ascii_uppercase()) {
        Some('K') => (&t[..t.len() - 1], 10),
        Some('M') => (&t[..t.len() - 1], 20),
        Some('G') => (&t[..t.len() - 1], 30),
        Some('T') => (&t[..t.len() - 1], 40),
        _ => (t, 0),
    };
    let x: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("{text:?} is not a size such as 8G, 512M or 1000000"))?;
    let bytes = x * (1u64 << shift) as f64;
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("{text:?} is not a size of at least one byte"));
    }
    Ok(bytes as u64)
}
