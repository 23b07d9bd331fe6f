//! The machine's motion model, the one print-time estimate: moves are planned as firmware plans
//! them — a trapezoidal speed profile per move at constant acceleration, with the speed carried
//! through each junction limited by a classic-jerk rule and by what the neighbouring moves can
//! accelerate or brake to.
//!
//! Place in the pipeline: vocabulary. The G-code writer (`emit`) plans every move it writes with
//! it for the header's estimate, the tools' extrusion time and the cooling's layer times;
//! `conduit check` plans every move it replays with it. Both stop the queue where firmware
//! empties it (a dwell, a heat-up wait, homing, a tool change), so the header and `check` agree
//! on a file the writer made.
//!
//! With `jerk = 0` every move starts and ends at standstill, and a move of length `L` at speed
//! `v` takes [`trapezoid_time`]: `L/v + v/a` when `L ≥ v²/a`, else `2·√(L/a)`.

/// Largest instantaneous speed change of an axis at a junction, mm/s: Marlin's default
/// classic jerk (and PrusaSlicer's `machine_max_jerk_x`/`_y` for Marlin), which both the header
/// and `check` plan with.
pub const JERK_MM_S: f64 = 10.0;

/// Highest feed rate planned, mm/s: a cap on the machine's speed, far above any print move.
pub const MAX_FEEDRATE_MM_S: f64 = 500.0;

/// Feed rate of a move before any `F` word, mm/s: what `check` assumes at power-on and the
/// writer for custom G-code moving before the writer's first `F`.
pub const DEFAULT_FEEDRATE_MM_S: f64 = 25.0;

/// One planned move.
#[derive(Debug, Clone, Copy)]
struct Block {
    /// Caller's id of the move (the G-code line in `check`), for [`Planner::times`].
    line: usize,
    length: f64,
    speed: f64,
    dir_in: [f64; 3],
    dir_out: [f64; 3],
}

/// Queues moves and adds their planned time to [`Planner::total`] at each [`Planner::flush`].
#[derive(Debug, Clone)]
pub struct Planner {
    accel: f64,
    jerk: f64,
    blocks: Vec<Block>,
    /// Entry speed of the first queued block when it follows committed blocks.
    entry: Option<f64>,
    /// Time of the moves committed so far, s.
    pub total: f64,
    /// Planned time of each committed move: (the id it was pushed with, s), in push order.
    pub times: Vec<(usize, f64)>,
}

/// Moves queued before the older half is committed. As in firmware, the queue is planned as if
/// it ended in a stop; blocks half a queue away from that end are (for all but very long
/// braking distances) planned exactly, so committing them keeps the running time current for
/// the heat-up rule without changing the estimate.
const QUEUE: usize = 64;

impl Planner {
    /// A planner with acceleration `accel` (mm/s²) and jerk `jerk` (mm/s, the largest
    /// instantaneous speed change of any axis at a junction).
    pub fn new(accel: f64, jerk: f64) -> Self {
        Self {
            accel,
            jerk: jerk.max(0.0),
            blocks: Vec::new(),
            entry: None,
            total: 0.0,
            times: Vec::new(),
        }
    }

    /// Queues a move of a G-code file as the firmware runs it, with id `id`: its path (arcs as
    /// sampled) at its feed capped at `max_feedrate` mm/s, or its E change when it does not
    /// move. `check` plans every move so, and the writer the moves of custom G-code.
    pub fn push_gcode_move(&mut self, id: usize, mv: &conduit_gcode::Move, max_feedrate: f64) {
        let v = mv.feed.min(max_feedrate);
        if mv.length > 0.0 {
            let path = &mv.path;
            let dir_in = direction(path.first(), path.get(1));
            let dir_out = direction(path.iter().rev().nth(1), path.last());
            self.push(id, mv.length, v, dir_in, dir_out);
        } else {
            self.push(id, mv.e.abs(), v, [0.0; 3], [0.0; 3]);
        }
    }

    /// Queues the move with id `line` (any number the caller finds it by) of `length` mm at `speed` mm/s, leaving in unit
    /// direction `dir_in` and arriving in `dir_out` (zero vectors for moves of E only).
    pub fn push(
        &mut self,
        line: usize,
        length: f64,
        speed: f64,
        dir_in: [f64; 3],
        dir_out: [f64; 3],
    ) {
        if !(length > 0.0 && speed > 0.0) {
            return;
        }
        self.blocks.push(Block {
            line,
            length,
            speed,
            dir_in,
            dir_out,
        });
        if self.blocks.len() >= QUEUE {
            self.plan(QUEUE / 2);
        }
    }

    /// Plans the queued moves to a standstill and adds their time.
    pub fn flush(&mut self) {
        self.plan(self.blocks.len());
    }

    /// Plans the queue as ending in a stop and commits the time of its first `commit` blocks.
    fn plan(&mut self, commit: usize) {
        let n = self.blocks.len();
        if n == 0 {
            return;
        }
        let a = self.accel;
        let b = &self.blocks;
        if !(a > 0.0 && a.is_finite()) {
            let mut t = 0.0;
            for k in b {
                let dt = k.length / k.speed;
                self.times.push((k.line, dt));
                t += dt;
            }
            self.total += t;
            self.blocks.clear();
            return;
        }
        // Junction speeds: j[i] is the speed entering block i; j[n] leaving the last.
        let mut j = vec![0.0; n + 1];
        j[0] = self.entry.unwrap_or(self.jerk.min(b[0].speed));
        j[n] = self.jerk.min(b[n - 1].speed);
        for i in 1..n {
            j[i] = self.junction(&b[i - 1], &b[i]);
        }
        for i in (0..n).rev() {
            j[i] = j[i].min((j[i + 1] * j[i + 1] + 2.0 * a * b[i].length).sqrt());
        }
        for i in 0..n {
            j[i + 1] = j[i + 1].min((j[i] * j[i] + 2.0 * a * b[i].length).sqrt());
        }
        let commit = commit.min(n);
        let mut t = 0.0;
        for (i, k) in b.iter().enumerate().take(commit) {
            let dt = block_time(k.length, k.speed, j[i], j[i + 1], a);
            self.times.push((k.line, dt));
            t += dt;
        }
        self.total += t;
        self.blocks.drain(..commit);
        self.entry = (!self.blocks.is_empty()).then_some(j[commit]);
    }

    /// Classic jerk: the highest speed at which no axis changes speed by more than `jerk`.
    fn junction(&self, prev: &Block, next: &Block) -> f64 {
        let v = prev.speed.min(next.speed);
        let moving = |d: &[f64; 3]| d.iter().any(|c| *c != 0.0);
        if !moving(&prev.dir_out) || !moving(&next.dir_in) {
            return v.min(self.jerk);
        }
        let max_delta = (0..3)
            .map(|k| (next.dir_in[k] - prev.dir_out[k]).abs())
            .fold(0.0, f64::max);
        if max_delta * v <= self.jerk {
            v
        } else {
            self.jerk / max_delta
        }
    }
}

/// Time of one move of `length` at cruise `speed`, entering at `entry` and leaving at `exit`
/// (both reachable: the planner's passes guarantee it), with acceleration `a`.
fn block_time(length: f64, speed: f64, entry: f64, exit: f64, a: f64) -> f64 {
    let accel_d = (speed * speed - entry * entry) / (2.0 * a);
    let decel_d = (speed * speed - exit * exit) / (2.0 * a);
    if accel_d + decel_d <= length {
        (speed - entry) / a + (speed - exit) / a + (length - accel_d - decel_d) / speed
    } else {
        let peak = ((2.0 * a * length + entry * entry + exit * exit) / 2.0).sqrt();
        ((peak - entry) + (peak - exit)).max(0.0) / a
    }
}

/// Time to cover `length` mm from standstill to standstill at cruise speed `v` (mm/s) and
/// acceleration `a` (mm/s²): `L/v + v/a` when the cruise speed is reached (L ≥ v²/a),
/// otherwise `2·√(L/a)` (a triangle profile). The closed form the planner reduces to without
/// jerk; used by the tests.
#[cfg(test)]
pub(crate) fn trapezoid_time(length: f64, v: f64, a: f64) -> f64 {
    if length <= 0.0 || v <= 0.0 {
        return 0.0;
    }
    if a <= 0.0 || !a.is_finite() {
        return length / v;
    }
    block_time(length, v, 0.0, 0.0, a)
}

/// Unit direction from `a` to `b` over their known axes (zero when either is missing or they
/// coincide).
fn direction(a: Option<&conduit_gcode::Position>, b: Option<&conduit_gcode::Position>) -> [f64; 3] {
    let (Some(a), Some(b)) = (a, b) else {
        return [0.0; 3];
    };
    let mut d = [0.0; 3];
    for k in 0..3 {
        d[k] = match (a[k], b[k]) {
            (Some(p), Some(q)) => q - p,
            _ => 0.0,
        };
    }
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if len > 0.0 {
        d.map(|c| c / len)
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const X: [f64; 3] = [1.0, 0.0, 0.0];
    const Y: [f64; 3] = [0.0, 1.0, 0.0];

    fn plan(jerk: f64, moves: &[(f64, [f64; 3])]) -> f64 {
        let mut p = Planner::new(1000.0, jerk);
        for &(len, d) in moves {
            p.push(0, len, 100.0, d, d);
        }
        p.flush();
        p.total
    }

    #[test]
    fn single_moves_match_the_closed_forms() {
        // 100 mm at 100 mm/s, 1000 mm/s²: 0.1 s up over 5 mm, 90 mm in 0.9 s, 0.1 s down.
        assert!((trapezoid_time(100.0, 100.0, 1000.0) - 1.1).abs() < 1e-12);
        // 1 mm never reaches 100 mm/s (that needs 10 mm): 2·√(L/a).
        assert!((trapezoid_time(1.0, 100.0, 1000.0) - 2.0 * 0.001f64.sqrt()).abs() < 1e-12);
        assert!((plan(0.0, &[(100.0, X)]) - 1.1).abs() < 1e-12);
        // With 10 mm/s jerk the move starts and ends at 10 mm/s: 2·0.09 s ramps over
        // 2·4.95 mm, 90.1 mm cruising.
        assert!((plan(10.0, &[(100.0, X)]) - (0.18 + 0.901)).abs() < 1e-12);
    }

    #[test]
    fn junctions_carry_speed_through_straight_lines_but_not_corners() {
        // Two collinear halves take as long as the whole.
        assert!((plan(0.0, &[(50.0, X), (50.0, X)]) - 1.1).abs() < 1e-12);
        // A 90° corner with 10 mm/s jerk: the junction is at 10 mm/s (each axis changes by 10).
        let corner = plan(10.0, &[(50.0, X), (50.0, Y)]);
        let half = 0.09 + 0.09 + (50.0 - 2.0 * 4.95) / 100.0;
        assert!((corner - 2.0 * half).abs() < 1e-12, "{corner}");
        // Without jerk the corner is a full stop: two 50 mm moves from rest.
        assert!((plan(0.0, &[(50.0, X), (50.0, Y)]) - 2.0 * 0.6).abs() < 1e-12);
        // Many short collinear moves are limited by acceleration, not by stops.
        let many = vec![(1.0, X); 100];
        assert!(
            (plan(0.0, &many) - 1.1).abs() < 1e-9,
            "{}",
            plan(0.0, &many)
        );
        let many = vec![(1.0, X); 1000];
        assert!(
            (plan(0.0, &many) - 10.1).abs() < 1e-9,
            "{}",
            plan(0.0, &many)
        );
    }
}
