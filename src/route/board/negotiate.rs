//! Negotiated congestion: every wire routed with the others' traces as a price, not a wall.
//!
//! Place in the pipeline: the first stage of [`Board::route_all`] with
//! [`Strategy::Negotiated`](crate::route::Strategy), before the rip-up rounds. The method is
//! PathFinder's (McMurchie and Ebeling, FPGA 1995), as FPGA and PCB routers use it, on the
//! router's own graph: the deflated perimeter traces, the direct connections, the infill and
//! squeeze grids and the staircase layer changes of each layer, built from the material less
//! other nets' pads (which stay hard obstacles).
//!
//! 1. Round 1 routes every wire in [`wire_order`](crate::route::wire_order); a link inside the
//!    keep-out of another net's trace (on its layer or the next) costs `factor` times more
//!    (the present-congestion cost), so routes share room only where going round costs more.
//! 2. After each round the wires whose channels overlap another net's (on their layer or the
//!    next) are in conflict. The cells where they overlap get [`HISTORY_STEP`] more history
//!    (a link costs `1 + history` times more, capped at [`HISTORY_CAP`]), the present factor
//!    grows by [`FACTOR_GROWTH`], and only the wires in conflict (with the wires that end on
//!    their traces) are ripped up and routed again, in wire order.
//! 3. When no wire is in conflict, after `negotiation_rounds` rounds, after [`STALL_ROUNDS`]
//!    rounds that leave no fewer wires in conflict than the best round, or at the deadline,
//!    conflicts left are settled: the wire in the most conflicts (the later in wire order on a
//!    tie) is ripped up until none is left, and the wires ripped are routed again with every
//!    other net's trace as an obstacle, in wire order. The rip-up rounds take it from there.
//!
//! Every step runs in a fixed order on data that depends only on the input, so the result does
//! too.

use super::{Board, Placed, Traces, boxes_meet};
use crate::geom::{ExPolygon, intersection, scaled};
use crate::route::congestion::History;
use crate::route::{Phase, RoundLog};
use std::collections::BTreeSet;
use std::sync::Arc;

/// Cost multiplier of links inside another net's keep-out in the first round: low, so the
/// first routes are close to the shortest and show where the board is crowded.
const FIRST_FACTOR: f64 = 1.5;

/// Growth of the present-congestion factor per round.
const FACTOR_GROWTH: f64 = 1.8;

/// History added per round to a cell where two nets' channels overlap.
const HISTORY_STEP: f64 = 0.5;

/// Most history a cell holds: links cost at most `1 + HISTORY_CAP` times more, which bounds how
/// far round a contested place a route is driven (and how far its search looks).
const HISTORY_CAP: f64 = 2.0;

/// Overlap of two channels (mm²) below which they do not count as in conflict: a sliver where
/// the polygonal ends of two traces leaving neighbouring pads graze, far narrower than the
/// `channel_extra` of plastic that still separates the traces themselves.
const CONFLICT_MM2: f64 = 0.01;

/// Rounds without fewer wires in conflict than the best so far after which negotiation stops.
const STALL_ROUNDS: usize = 3;

/// Two wires of different nets whose channels overlap, and where.
#[derive(Debug, Clone)]
struct Conflict {
    /// The two wires.
    wires: [usize; 2],
    /// Their layers.
    layers: [usize; 2],
    /// The overlap of their channels (in xy).
    area: Vec<ExPolygon>,
}

impl Board<'_> {
    /// Routes every wire by negotiated congestion (see the module doc); returns the rounds run
    /// and the wires that were still in conflict when they stopped.
    pub(super) fn negotiate(&mut self, order: &[usize], log: &mut Vec<RoundLog>) -> (usize, usize) {
        let mut rank = vec![usize::MAX; self.wires.len()];
        for (k, &i) in order.iter().enumerate() {
            rank[i] = k;
        }
        let cell = scaled(self.params.grid_step / 2.0).max(1);
        let mut history = History::new(cell, HISTORY_CAP);
        let mut factor = FIRST_FACTOR;
        let mut todo: Vec<usize> = order.to_vec();
        let mut conflicts: Vec<Conflict> = Vec::new();
        let mut in_conflict = 0;
        let mut rounds = 0;
        let (mut best, mut best_round) = (usize::MAX, 0);
        let mut best_state = None;
        for round in 1..=self.params.negotiation_rounds.max(1) {
            if self.past_deadline() {
                break;
            }
            rounds = round;
            // The wires to route: those in conflict (all of them in the first round), and the
            // wires ripped up with them because they end on their traces.
            let mut ripped = todo.clone();
            for &i in &todo {
                self.rip_up(i, &mut ripped);
            }
            ripped.sort_by_key(|&i| rank[i]);
            ripped.dedup();
            let traces = Traces::Priced {
                factor,
                history: Arc::new(history.clone()),
            };
            let settled = self.wires.len() - ripped.len();
            for (k, &i) in ripped.iter().enumerate() {
                self.route_with(i, &traces);
                self.tell_negotiation(settled + k + 1, 0, round, in_conflict);
            }
            conflicts = self.conflicts();
            let wires: BTreeSet<usize> = conflicts.iter().flat_map(|c| c.wires).collect();
            in_conflict = wires.len();
            self.tell_negotiation(self.wires.len(), 0, round, in_conflict);
            log.push(self.log_line(Phase::Negotiation, round, in_conflict));
            if conflicts.is_empty() {
                break;
            }
            for c in &conflicts {
                for l in c.layers {
                    history.add(l, &c.area, HISTORY_STEP);
                }
            }
            if in_conflict < best {
                best = in_conflict;
                best_round = round;
                best_state = Some((self.placed.clone(), self.routes.clone(), conflicts.clone()));
            } else if round >= best_round + STALL_ROUNDS {
                // The conflicts left are ones the fixed graph has no way round (a fine-pitch
                // pad row, where only rings formed round a trace find room): settled below.
                break;
            }
            factor *= FACTOR_GROWTH;
            todo = wires.into_iter().collect();
        }
        if let Some((placed, routes, kept)) = best_state.filter(|_| in_conflict > best) {
            // The rounds after the best one did no better: settle from the best.
            (self.placed, self.routes, conflicts, in_conflict) = (placed, routes, kept, best);
        }
        let ripped = self.settle(&conflicts, &rank);
        for (k, &i) in ripped.iter().enumerate() {
            self.route_one(i);
            self.tell_negotiation(self.wires.len() - ripped.len() + k + 1, 0, rounds, 0);
        }
        if !ripped.is_empty() {
            log.push(self.log_line(Phase::Settle, 1, 0));
        }
        (rounds, in_conflict)
    }

    /// Every pair of wires of different nets whose channels overlap on one layer or two
    /// adjacent ones, by increasing wire indices.
    fn conflicts(&self) -> Vec<Conflict> {
        let mut out: Vec<Conflict> = Vec::new();
        for l in 0..self.placed.len() {
            for (k, p) in self.placed[l].iter().enumerate() {
                let same = self.placed[l][k + 1..].iter().map(|q| (l, q));
                let above = self
                    .placed
                    .get(l + 1)
                    .into_iter()
                    .flatten()
                    .map(|q| (l + 1, q));
                for (lq, q) in same.chain(above) {
                    if let Some(area) = overlap(p, q) {
                        let (a, b) = if p.wire < q.wire {
                            ((p.wire, l), (q.wire, lq))
                        } else {
                            ((q.wire, lq), (p.wire, l))
                        };
                        out.push(Conflict {
                            wires: [a.0, b.0],
                            layers: [a.1, b.1],
                            area,
                        });
                    }
                }
            }
        }
        out.sort_by_key(|c| (c.wires, c.layers));
        out
    }

    /// Rips up wires until no conflict is left: each time the wire in the most conflicts, the
    /// later in wire order (`rank`) on a tie. Returns the wires ripped (with the wires that
    /// ended on their traces), in wire order.
    fn settle(&mut self, conflicts: &[Conflict], rank: &[usize]) -> Vec<usize> {
        let mut pairs: BTreeSet<(usize, usize)> =
            conflicts.iter().map(|c| (c.wires[0], c.wires[1])).collect();
        let mut ripped: Vec<usize> = Vec::new();
        while !pairs.is_empty() {
            let mut count = vec![0usize; self.wires.len()];
            for &(a, b) in &pairs {
                count[a] += 1;
                count[b] += 1;
            }
            let Some(worst) = (0..self.wires.len())
                .filter(|&i| count[i] > 0)
                .max_by_key(|&i| (count[i], rank[i]))
            else {
                break;
            };
            let from = ripped.len();
            self.rip_up(worst, &mut ripped);
            let gone: BTreeSet<usize> = ripped[from..].iter().copied().collect();
            pairs.retain(|(a, b)| !gone.contains(a) && !gone.contains(b));
        }
        ripped.sort_by_key(|&i| rank[i]);
        ripped.dedup();
        ripped
    }
}

/// Where the channels of `p` and `q` overlap, if they are of different nets and do.
fn overlap(p: &Placed, q: &Placed) -> Option<Vec<ExPolygon>> {
    if p.net == q.net || !boxes_meet(&p.bbox, &q.bbox) {
        return None;
    }
    let common = intersection(&p.channel, &q.channel);
    (common.iter().map(ExPolygon::area_mm2).sum::<f64>() > CONFLICT_MM2).then_some(common)
}
