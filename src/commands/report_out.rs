//! How a command that computes one report prints it: one JSON object on a line, or its table.

use anyhow::Result;
use serde::Serialize;

/// Prints `report` as one line of JSON when `json`, else the text `table` makes of it.
pub fn print_report<R: Serialize>(
    json: bool,
    report: &R,
    table: impl FnOnce(&R) -> String,
) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string(report)?);
    } else {
        print!("{}", table(report));
    }
    Ok(())
}
