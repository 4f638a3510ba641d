//! Exact quantiles of data that is read in passes rather than held: a
//! counting pass and selection passes (radix selection on the values'
//! total order).
//!
//! A quantile by linear interpolation needs the order statistics at ranks
//! ⌊p(n−1)⌋ and ⌈p(n−1)⌉ (`stats::position`). The first pass counts each
//! group's values by the top 16 bits of their order key (giving n, hence
//! the ranks, and the 1/65 536 slice of the key range holding each rank);
//! each further pass either narrows a rank's slice by the next 16 bits or,
//! once the slice holds at most [`COLLECT_MAX`] values, collects them and
//! sorts. So the values found are the run's own (bit for bit what sorting
//! everything would give), memory is bounded by the histograms and
//! [`COLLECT_MAX`], and a typical run needs two passes.

use super::stats::position;
use super::ReduceError;

/// Values a rank's slice may hold to be collected and sorted (8 bytes each).
pub(crate) const COLLECT_MAX: u64 = 1 << 18;

const DIGIT_BITS: u32 = 16;
const BUCKETS: usize = 1 << DIGIT_BITS;

/// A u64 whose unsigned order is `f64::total_cmp`'s.
fn key(v: f64) -> u64 {
    let b = v.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

/// The f64 of an order key.
fn value(k: u64) -> f64 {
    f64::from_bits(if k >> 63 == 1 { k & !(1 << 63) } else { !k })
}

/// One order statistic being searched for.
#[derive(Debug, Clone)]
struct Rank {
    group: usize,
    /// The key's top `bits` bits, once known.
    prefix: u64,
    bits: u32,
    /// Rank among the values with that prefix.
    rank: u64,
    /// Values with that prefix.
    count: u64,
    found: Option<f64>,
}

impl Rank {
    fn matches(&self, k: u64) -> bool {
        self.bits == 0 || k >> (64 - self.bits) == self.prefix
    }
}

/// Narrows `r` to the bucket of `hist` (counts by the next digit) holding its rank.
fn narrow(r: &mut Rank, hist: &[u64]) {
    let mut below = 0;
    for (d, &c) in hist.iter().enumerate() {
        if r.rank < below + c {
            r.prefix = (r.prefix << DIGIT_BITS) | d as u64;
            r.bits += DIGIT_BITS;
            r.rank -= below;
            r.count = c;
            if r.bits == 64 {
                r.found = Some(value(r.prefix));
            }
            return;
        }
        below += c;
    }
    unreachable!("rank {} beyond the {below} values counted", r.rank);
}

/// The `p`-quantiles asked for by `requests` (group, p), each over the
/// values of its group, as `stats::quantile_sorted` of the sorted group
/// would give (`None` for an empty group); and every group's size.
///
/// `pass` is called once per pass; it must call its argument with
/// (group, value) for every value of every group (`group < groups`), the
/// same values each time.
pub(crate) fn quantiles<F>(groups: usize, requests: &[(usize, f64)], mut pass: F) -> Result<(Vec<Option<f64>>, Vec<u64>), ReduceError>
where
    F: FnMut(&mut dyn FnMut(usize, f64)) -> Result<(), ReduceError>,
{
    // Counting pass: per group, counts by the top digit.
    let mut wanted = vec![false; groups];
    for &(g, _) in requests {
        wanted[g] = true;
    }
    let mut sizes = vec![0u64; groups];
    let mut hists: Vec<Vec<u64>> = wanted.iter().map(|&w| if w { vec![0; BUCKETS] } else { Vec::new() }).collect();
    pass(&mut |g, v| {
        sizes[g] += 1;
        if let Some(h) = hists[g].get_mut((key(v) >> (64 - DIGIT_BITS)) as usize) {
            *h += 1;
        }
    })?;
    // The ranks each request needs.
    let mut ranks: Vec<Rank> = Vec::new();
    let rank_of = |g: usize, rank: u64, ranks: &mut Vec<Rank>| -> usize {
        if let Some(i) = ranks.iter().position(|r| r.group == g && r.rank == rank && r.bits == 0) {
            return i;
        }
        ranks.push(Rank {
            group: g,
            prefix: 0,
            bits: 0,
            rank,
            count: sizes[g],
            found: None,
        });
        ranks.len() - 1
    };
    let plan: Vec<Option<(usize, usize, f64)>> = requests
        .iter()
        .map(|&(g, p)| {
            (sizes[g] > 0).then(|| {
                let (lo, hi, frac) = position(sizes[g] as usize, p);
                (rank_of(g, lo as u64, &mut ranks), rank_of(g, hi as u64, &mut ranks), frac)
            })
        })
        .collect();
    for r in &mut ranks {
        narrow(r, &hists[r.group]);
    }
    drop(hists);
    // Selection passes until every rank is found.
    loop {
        let open: Vec<usize> = (0..ranks.len()).filter(|&i| ranks[i].found.is_none()).collect();
        if open.is_empty() {
            break;
        }
        let mut by_group: Vec<Vec<usize>> = vec![Vec::new(); groups];
        for &i in &open {
            by_group[ranks[i].group].push(i);
        }
        let collect: Vec<bool> = ranks.iter().map(|r| r.count <= COLLECT_MAX).collect();
        let mut collected: Vec<Vec<f64>> = vec![Vec::new(); ranks.len()];
        let mut hists: Vec<Vec<u64>> = ranks
            .iter()
            .enumerate()
            .map(|(i, r)| {
                if r.found.is_none() && !collect[i] {
                    vec![0; BUCKETS]
                } else {
                    Vec::new()
                }
            })
            .collect();
        pass(&mut |g, v| {
            let k = key(v);
            for &i in &by_group[g] {
                let r = &ranks[i];
                if r.matches(k) {
                    if collect[i] {
                        collected[i].push(v);
                    } else {
                        hists[i][((k << r.bits) >> (64 - DIGIT_BITS)) as usize] += 1;
                    }
                }
            }
        })?;
        for i in open {
            if collect[i] {
                let values = &mut collected[i];
                if values.len() as u64 != ranks[i].count {
                    return Err(ReduceError::RunChanged);
                }
                values.sort_unstable_by(f64::total_cmp);
                ranks[i].found = Some(values[ranks[i].rank as usize]);
            } else {
                if hists[i].iter().sum::<u64>() != ranks[i].count {
                    return Err(ReduceError::RunChanged);
                }
                narrow(&mut ranks[i], &hists[i]);
            }
        }
    }
    let out = plan
        .into_iter()
        .map(|p| {
            p.map(|(lo, hi, frac)| {
                let (lo, hi) = (ranks[lo].found.expect("found"), ranks[hi].found.expect("found"));
                lo + (hi - lo) * frac
            })
        })
        .collect();
    Ok((out, sizes))
}

#[cfg(test)]
mod tests {
    use super::super::stats::quantile_sorted;
    use super::*;

    #[test]
    fn keys_order_like_total_cmp() {
        let vals = [
            f64::NEG_INFINITY,
            -1e300,
            -1.0,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            1.0,
            1e300,
            f64::INFINITY,
        ];
        for w in vals.windows(2) {
            assert!(key(w[0]) < key(w[1]), "{w:?}");
        }
        for v in vals {
            assert_eq!(value(key(v)).to_bits(), v.to_bits());
        }
    }

    fn check(values: &[Vec<f64>], ps: &[f64]) {
        let requests: Vec<(usize, f64)> = (0..values.len()).flat_map(|g| ps.iter().map(move |&p| (g, p))).collect();
        let (got, sizes) = quantiles(values.len(), &requests, |f| {
            for (g, vs) in values.iter().enumerate() {
                for &v in vs {
                    f(g, v);
                }
            }
            Ok(())
        })
        .unwrap();
        for (&(g, p), q) in requests.iter().zip(got) {
            assert_eq!(sizes[g], values[g].len() as u64);
            let mut sorted = values[g].clone();
            sorted.sort_unstable_by(f64::total_cmp);
            let want = (!sorted.is_empty()).then(|| quantile_sorted(&sorted, p));
            assert_eq!(q.map(f64::to_bits), want.map(f64::to_bits), "group {g}, p {p}");
        }
    }

    #[test]
    fn equals_sorting_bit_for_bit() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let ps = [0.0, 0.1, 0.25, 1.0 / 3.0, 0.5, 2.0 / 3.0, 0.75, 0.9, 1.0];
        // Spread values, ties, one value, an empty group, and a group whose
        // values share their top bits (so selection narrows more than once).
        let spread: Vec<f64> = (0..5000).map(|_| (next() >> 11) as f64 / (1u64 << 53) as f64 - 0.5).collect();
        let ties: Vec<f64> = (0..3000).map(|_| (next() % 7) as f64 * 0.25 - 0.5).collect();
        let close: Vec<f64> = (0..(COLLECT_MAX as usize + 5000))
            .map(|i| 1.0 + (i as f64 * 7919.0 % 1e5) * 1e-12)
            .collect();
        check(&[spread, ties, vec![3.5], vec![], close], &ps);
    }
}
