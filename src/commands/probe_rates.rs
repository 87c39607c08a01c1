//! What `rins probe --scan` prints per rate, for the sensor block and the GNSS receiver alike.

use serde_json::{Value, json};

/// Each rate's report as JSON (`report`), with its `baud`.
pub(super) fn rates_json<R>(results: &[(u32, R)], report: impl Fn(&R) -> Value) -> Vec<Value> {
    results
        .iter()
        .map(|(baud, r)| {
            let mut v = report(r);
            v["baud"] = json!(baud);
            v
        })
        .collect()
}
