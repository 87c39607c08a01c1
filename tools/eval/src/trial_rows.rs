//! The rows of a per-trial table that lists every unit's run and then the fused run.

/// Every unit's run of a trial, then the fused run, each with the row's first two cells: the
/// trial's name and length (s, one decimal) on the first row only, blank on the others.
pub(crate) fn unit_then_fused_rows<'a, R>(
    name: &'a str,
    duration_s: f64,
    single: &'a [R],
    fused: &'a R,
) -> impl Iterator<Item = (&'a str, String, &'a R)> {
    single
        .iter()
        .chain(std::iter::once(fused))
        .enumerate()
        .map(move |(k, run)| {
            if k == 0 {
                (name, format!("{duration_s:.1}"), run)
            } else {
                ("", String::new(), run)
            }
        })
}
