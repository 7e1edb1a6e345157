//! The benchmarks' `--json` reports: checked before a benchmark starts, written atomically.

use anyhow::{Context, Result};
use igi_render::image::output::{check_writable, write_atomically};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Checks, before a benchmark starts, that its `--json` report can be written.
pub fn check_json(json: Option<&Path>) -> Result<()> {
    json.map(check_writable).transpose().context("--json")?;
    Ok(())
}

/// Writes a benchmark's report as pretty JSON; `path` is replaced at once.
pub fn write_json(path: &Path, report: &impl Serialize) -> Result<()> {
    let json = serde_json::to_string_pretty(report)?;
    write_atomically(path, |out| out.write_all(json.as_bytes()))
        .with_context(|| format!("cannot write {}", path.display()))
}
