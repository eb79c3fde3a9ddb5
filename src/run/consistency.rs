//! A saved state checked for meaning, not only for form: a state file whose checksum was recomputed
//! after an edit, or written by a faulty program, must not be reported as a run. Each group must hold
//! exactly the lines of its batches, and every counter must be one that those lines can give (pairs
//! and escapes no more than the crossings, crossings no more than one per line and triangle), so that
//! a forged count can neither wrap around nor send an estimator into a loop as long as the count.

use super::plan::{BatchPlan, BatchSet};
use crate::sample::exact::ExactSum;
use crate::sample::tally::Counters;

/// The batches a state says are done, refused by name when its ranges are empty, overlap or reach
/// beyond the plan.
pub(super) fn done_batches(ranges: &[[u64; 2]], plan: BatchPlan) -> Result<BatchSet, String> {
    let batches = plan.batches();
    if let Some(r) = ranges.iter().find(|r| r[0] >= r[1] || r[1] > batches) {
        return Err(format!(
            "done batches {}..{}, not a range within its {batches} batches",
            r[0], r[1]
        ));
    }
    let done = BatchSet::from_ranges(ranges.iter().map(|r| r[0]..r[1]));
    let listed = ranges.iter().map(|r| u128::from(r[1] - r[0])).sum::<u128>();
    if u128::from(done.len()) != listed {
        return Err("batches listed as done more than once".into());
    }
    Ok(done)
}

/// The plan's last batch when it has fewer lines than the others: kept apart from the groups in a state
/// ([`super::state::RunState`]).
pub(super) fn partial_batch(plan: BatchPlan) -> Option<u64> {
    let last = plan.batches().checked_sub(1)?;
    ((plan.batch_len(last) as u64) < plan.batch_size).then_some(last)
}

/// The lines each of `groups` groups holds when the batches `done` are done: batch `b` belongs to group
/// `b mod groups`, and the partial last batch to none (it is kept apart). Each range adds its whole
/// cycles to every group and its remainder, a run of consecutive groups, through a difference list.
pub(super) fn group_lines(plan: BatchPlan, done: &BatchSet, groups: usize) -> Vec<u64> {
    let g = groups as u64;
    let mut whole_cycles = 0u64;
    let mut steps = vec![0i64; 2 * groups + 1];
    for r in done.ranges() {
        let n = r.end - r.start;
        whole_cycles += n / g;
        let first = (r.start % g) as usize;
        steps[first] += 1;
        steps[first + (n % g) as usize] -= 1;
    }
    let mut batches = vec![whole_cycles; groups];
    let mut running = 0i64;
    for (k, step) in steps.iter().enumerate().take(2 * groups) {
        running += step;
        batches[k % groups] += running as u64;
    }
    if let Some(last) = partial_batch(plan).filter(|&b| done.contains(b)) {
        batches[(last % g) as usize] -= 1;
    }
    batches.iter().map(|&b| b * plan.batch_size).collect()
}

/// Checks that a tally's counters are ones that `lines` lines through a scene of `triangles` triangles
/// can give.
pub(super) fn check_counters(c: &Counters, lines: u64, triangles: u64) -> Result<(), String> {
    if c.lines != lines {
        return Err(format!(
            "it holds {} lines, where its batches hold {lines}",
            c.lines
        ));
    }
    let wide = u128::from;
    let most_hits = wide(lines) * wide(triangles);
    let checks = [
        (
            wide(c.hits) <= most_hits,
            "more crossings than its lines can make",
        ),
        (c.misses <= lines, "more lines that miss than lines"),
        (c.pairs <= c.hits, "more pairs than crossings"),
        (
            wide(c.pairs) + wide(c.escapes) + wide(c.unpaired) <= wide(c.hits) + wide(lines),
            "more segments than its crossings cut its lines into",
        ),
        (
            c.absorbed <= c.unpaired,
            "more absorbed segments than unpaired ones",
        ),
        (
            c.degenerate_pairs <= c.pairs,
            "more degenerate pairs than pairs",
        ),
        (c.cmi_pairs <= c.pairs, "more pairs in eq. (27) than pairs"),
        (
            wide(c.env_pairs) <= wide(c.escapes) + wide(c.misses),
            "more segments to the environment than escapes and misses",
        ),
        (
            wide(c.coincident_crossings) <= most_hits,
            "more coincident crossings than its lines can make",
        ),
    ];
    match checks.iter().find(|(holds, _)| !holds) {
        Some((_, problem)) => Err(format!("{problem} ({c:?})")),
        None => Ok(()),
    }
}

/// Checks that per-patch sums of eq. (27)'s log kernel are ones their counts of terms can give: each
/// term is the `log2` of a normal f64 ([`crate::sample::kernel::kernel_without_pi`]), within
/// (-1075, 1024), so a sum beyond that many times its count is forged (and could overflow a merge).
pub(super) fn check_kernel_sums(sums: &[ExactSum], ends: &[u64], what: &str) -> Result<(), String> {
    let most = |e: u64| MOST_LOG2_KERNEL * e as f64;
    match sums
        .iter()
        .zip(ends)
        .position(|(s, &e)| s.value().abs() > most(e))
    {
        Some(i) => Err(format!(
            "{what}: patch {i}'s sum {} is beyond what its {} terms can add up to",
            sums[i].value(),
            ends[i]
        )),
        None => Ok(()),
    }
}

/// The largest |log2| of a normal f64.
const MOST_LOG2_KERNEL: f64 = 1075.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// The lines per group from the difference list agree with counting batch by batch.
    #[test]
    fn group_lines_agree_with_counting_each_batch() {
        for (lines, groups) in [
            (70_000u64, 16usize),
            (262_144, 16),
            (1_000_000, 7),
            (5_000, 2),
        ] {
            let plan = BatchPlan::new(lines);
            let batches = plan.batches();
            let sets = [
                BatchSet::first(batches),
                BatchSet::from_ranges([1..3, 5..batches.min(40), batches - 1..batches]),
                BatchSet::first(1),
                BatchSet::default(),
            ];
            for done in sets {
                let mut expected = vec![0u64; groups];
                for r in done.ranges() {
                    for b in r.clone() {
                        if Some(b) != partial_batch(plan) {
                            expected[(b % groups as u64) as usize] += plan.batch_len(b) as u64;
                        }
                    }
                }
                assert_eq!(
                    group_lines(plan, &done, groups),
                    expected,
                    "{lines} {groups}"
                );
            }
        }
    }

    /// A counter no line could give is refused, naming it.
    #[test]
    fn impossible_counters_are_refused() {
        let ok = Counters {
            lines: 100,
            hits: 150,
            pairs: 40,
            escapes: 60,
            unpaired: 20,
            misses: 10,
            ..Counters::default()
        };
        assert_eq!(check_counters(&ok, 100, 12), Ok(()));
        assert!(check_counters(&ok, 99, 12)
            .unwrap_err()
            .contains("100 lines"));
        let forged = Counters {
            pairs: u64::MAX,
            ..ok
        };
        assert!(check_counters(&forged, 100, 12)
            .unwrap_err()
            .contains("more pairs than crossings"));
        let wrapped = Counters {
            hits: u64::MAX,
            ..ok
        };
        assert!(check_counters(&wrapped, 100, 12)
            .unwrap_err()
            .contains("crossings than its lines"));
    }

    /// Per-patch sums of the log kernel beyond 1075 bits a term are refused, naming the patch.
    #[test]
    fn kernel_sums_beyond_their_terms_are_refused() {
        let sums = [ExactSum::of(-2000.0), ExactSum::of(5000.0)];
        assert_eq!(check_kernel_sums(&sums, &[2, 5], "sums"), Ok(()));
        let message = check_kernel_sums(&sums, &[1, 5], "sums").unwrap_err();
        assert!(message.contains("patch 0"), "{message}");
        assert!(check_kernel_sums(&sums, &[2, 4], "sums").is_err());
    }
}
