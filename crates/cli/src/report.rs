//! `vworks report`: a run's log turned into its HTML report.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::output::plural;

pub(crate) fn write_report(log: &Path, output: Option<PathBuf>) -> Result<ExitCode, String> {
    let out = output.unwrap_or_else(|| log.with_extension("html"));
    let (_, code) = report_to(log, &out)?;
    Ok(code)
}

/// Writes the report of `log` to `out` and says so on stderr; the exit code is a failure
/// if the log is damaged (the report shows what was read).
pub(crate) fn report_to(
    log: &Path,
    out: &Path,
) -> Result<(vworks_report::Written, ExitCode), String> {
    let written = vworks_report::write_report(log, out).map_err(|e| e.to_string())?;
    eprintln!(
        "wrote {} ({}, {}, {}{})",
        out.display(),
        plural(written.report.timelines.len(), "robot"),
        plural(written.events, "event"),
        plural(written.report.collisions.len(), "collision"),
        if written.has_view {
            ""
        } else {
            "; no 3D view: the log has no poses"
        }
    );
    if let Some((read, e)) = &written.damage {
        eprintln!(
            "warning: {} is unfinished or damaged after {read} messages ({e}); the report shows what was read",
            log.display()
        );
        return Ok((written, ExitCode::FAILURE));
    }
    Ok((written, ExitCode::SUCCESS))
}
