//! An experiment split across machines: `--shard K/N` runs the K-th of N deterministic shares of
//! its units of work into its own folder (`shards/K-of-N/` under the results folder), never the
//! final outputs; `--merge` puts the shares back together ([`super::merge`]).
//!
//! Units are dealt by expected cost, longest first onto the share that would finish earliest
//! (LPT scheduling). A unit may name a setup it shares with others (a sweep's ground truth, a
//! scene's structures), paid once by every share that runs any of those units. Two deals are
//! made, unit by unit and by groups of units sharing a setup (cut into pieces only where a group
//! costs more than a fair share), and the one that finishes sooner is kept: a setup is paid again
//! only where that finishes sooner. The deal depends on the experiment
//! alone (costs and key texts), not on the machine, so every shard and the merge compute it alike.

pub use crate::experiment::args::{Shard, MAX_SHARDS};

/// What dealing a unit costs: its own work, and a setup it may share with other units.
#[derive(Clone, Debug, PartialEq)]
pub struct Cost {
    /// Expected work (rays traced, or any measure proportional to time).
    pub work: f64,
    /// A setup shared with the units naming the same id, and its cost, paid once per share.
    pub setup: Option<(u64, f64)>,
    /// Breaks ties between equal costs: the unit's key text.
    pub tie: String,
}

/// The share (0-based) of each unit among `count` shares, and each share's expected work
/// (setups included); see the module documentation. Of two deals, by groups ([`by_groups`]) and
/// unit by unit ([`by_units`]), the one whose last share finishes first (by groups on a tie).
pub fn deal(costs: &[Cost], count: u32) -> (Vec<u32>, Vec<f64>) {
    let last = |d: &(Vec<u32>, Vec<f64>)| d.1.iter().cloned().fold(0.0, f64::max);
    let (groups, units) = (by_groups(costs, count), by_units(costs, count));
    if last(&units) < last(&groups) {
        units
    } else {
        groups
    }
}

/// Longest unit first onto the share that would finish earliest, a share that does not yet hold
/// the unit's setup paying it: balances well, but may pay a costly setup on every share.
fn by_units(costs: &[Cost], count: u32) -> (Vec<u32>, Vec<f64>) {
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by(|&a, &b| {
        costs[b]
            .work
            .total_cmp(&costs[a].work)
            .then_with(|| costs[a].tie.cmp(&costs[b].tie))
    });
    let mut load = vec![0.0f64; count as usize];
    let mut holds: Vec<Vec<u64>> = vec![Vec::new(); count as usize];
    let mut share = vec![0u32; costs.len()];
    for i in order {
        let c = &costs[i];
        let finish = |s: usize| {
            load[s]
                + c.work
                + match c.setup {
                    Some((id, cost)) if !holds[s].contains(&id) => cost,
                    _ => 0.0,
                }
        };
        let best = (0..count as usize)
            .min_by(|&a, &b| finish(a).total_cmp(&finish(b)))
            .expect("at least one share");
        load[best] = finish(best);
        if let Some((id, _)) = c.setup {
            if !holds[best].contains(&id) {
                holds[best].push(id);
            }
        }
        share[i] = best as u32;
    }
    (share, load)
}

/// Units sharing a setup form a group. A group costing more than a fair share (the total over
/// `count`) is cut into as many pieces as it takes to fit one (each piece pays the setup again,
/// at most one piece per unit and per share); then pieces are dealt whole, longest first, onto
/// the share that would finish earliest, where a share already holding the setup pays it once.
fn by_groups(costs: &[Cost], count: u32) -> (Vec<u32>, Vec<f64>) {
    let by_tie = |a: &usize, b: &usize| {
        costs[*b]
            .work
            .total_cmp(&costs[*a].work)
            .then_with(|| costs[*a].tie.cmp(&costs[*b].tie))
    };
    // Groups: units of one setup id, or a unit without one alone.
    let mut groups: Vec<(Option<u64>, f64, Vec<usize>)> = Vec::new();
    for (i, c) in costs.iter().enumerate() {
        match c.setup.and_then(|(id, _)| groups.iter_mut().find(|g| g.0 == Some(id))) {
            Some(g) => g.2.push(i),
            None => groups.push((c.setup.map(|s| s.0), c.setup.map_or(0.0, |s| s.1), vec![i])),
        }
    }
    let total: f64 = groups
        .iter()
        .map(|(_, setup, units)| setup + units.iter().map(|&i| costs[i].work).sum::<f64>())
        .sum();
    let fair = total / count as f64;
    // Pieces: (setup id, setup cost, units), each group's units dealt longest first among its pieces.
    let mut pieces: Vec<(Option<u64>, f64, Vec<usize>)> = Vec::new();
    for (id, setup, mut units) in groups {
        let whole = setup + units.iter().map(|&i| costs[i].work).sum::<f64>();
        let cut = if fair > 0.0 { (whole / fair).ceil() as usize } else { 1 };
        let cut = cut.clamp(1, units.len().min(count as usize));
        units.sort_by(by_tie);
        let mut parts: Vec<(f64, Vec<usize>)> = vec![(setup, Vec::new()); cut];
        for i in units {
            let p = (0..cut)
                .min_by(|&a, &b| parts[a].0.total_cmp(&parts[b].0))
                .expect("one piece");
            parts[p].0 += costs[i].work;
            parts[p].1.push(i);
        }
        pieces.extend(parts.into_iter().map(|(_, units)| (id, setup, units)));
    }
    let work = |p: &(Option<u64>, f64, Vec<usize>)| p.2.iter().map(|&i| costs[i].work).sum::<f64>();
    pieces.sort_by(|a, b| {
        (work(b) + b.1)
            .total_cmp(&(work(a) + a.1))
            .then_with(|| costs[a.2[0]].tie.cmp(&costs[b.2[0]].tie))
    });
    let mut load = vec![0.0f64; count as usize];
    let mut holds: Vec<Vec<u64>> = vec![Vec::new(); count as usize];
    let mut share = vec![0u32; costs.len()];
    for piece in &pieces {
        let (id, setup, units) = piece;
        let finish = |s: usize| {
            let held = id.is_some_and(|id| holds[s].contains(&id));
            load[s] + work(piece) + if held { 0.0 } else { *setup }
        };
        let best = (0..count as usize)
            .min_by(|&a, &b| finish(a).total_cmp(&finish(b)))
            .expect("at least one share");
        load[best] = finish(best);
        if let Some(id) = id {
            if !holds[best].contains(id) {
                holds[best].push(*id);
            }
        }
        for &i in units {
            share[i] = best as u32;
        }
    }
    (share, load)
}

/// `--dry-run --shard`'s first line: the share's units and expected work among all shares'.
pub fn share_line(name: &str, shard: Shard, units: usize, what: &str, loads: &[f64]) -> String {
    let total: f64 = loads.iter().sum::<f64>().max(1.0);
    let shares: Vec<String> = loads.iter().map(|r| format!("{:.1} %", 100.0 * r / total)).collect();
    format!(
        "{name}: shard {shard}: {units} {what}, {:.1} % of the expected work, setups included (shares: {})\n",
        100.0 * loads[shard.index as usize - 1] / total,
        shares.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cost(work: f64, setup: Option<(u64, f64)>, tie: &str) -> Cost {
        Cost {
            work,
            setup,
            tie: tie.into(),
        }
    }

    #[test]
    fn longest_first_onto_the_share_that_finishes_earliest() {
        let costs: Vec<Cost> = [5.0, 4.0, 3.0, 3.0, 2.0, 2.0, 1.0]
            .iter()
            .enumerate()
            .map(|(i, &w)| cost(w, None, &i.to_string()))
            .collect();
        let (share, load) = deal(&costs, 2);
        assert_eq!(load.iter().sum::<f64>(), 20.0);
        assert_eq!(load, vec![10.0, 10.0], "{share:?}");
        assert_eq!(deal(&costs, 2), (share, load), "deterministic");
        let (one, _) = deal(&costs, 1);
        assert!(one.iter().all(|&s| s == 0));
    }

    #[test]
    fn costly_shared_setups_keep_their_units_together_cheap_ones_do_not() {
        // Two setups of 100, each with four units of 1, on two shares: one group each finishes at
        // 104; dealing unit by unit would pay both setups on both shares (204).
        let costly: Vec<Cost> = (0..8)
            .map(|i| cost(1.0, Some((i / 4, 100.0)), &i.to_string()))
            .collect();
        let (share, load) = deal(&costly, 2);
        assert_eq!(load, vec![104.0, 104.0], "{share:?}");
        assert!(share[..4].iter().all(|&s| s == share[0]) && share[4..].iter().all(|&s| s == share[4]));
        assert_ne!(share[0], share[4]);
        // One such group on four shares: paying the setup on each finishes at 101, sooner than 104.
        let (share, load) = deal(&costly[..4], 4);
        assert_eq!(load, vec![101.0; 4], "{share:?}");
        let cheap: Vec<Cost> = (0..4).map(|i| cost(10.0, Some((7, 0.5)), &i.to_string())).collect();
        let (mut share, _) = deal(&cheap, 4);
        share.sort_unstable();
        assert_eq!(share, vec![0, 1, 2, 3]);
    }

    #[test]
    fn shard_texts_parse_and_bad_ones_are_refused() {
        assert_eq!("2/8".parse::<Shard>(), Ok(Shard { index: 2, count: 8 }));
        for bad in ["0/2", "3/2", "1/0", "2", "a/b", "1/10001"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
