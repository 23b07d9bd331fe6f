//! An edited host file checked against the host's original: what `conduit postprocess` promises,
//! tested on the output alone.
//!
//! Place in the pipeline: beside [`super::rewrite`], for tests and for users who want proof; it
//! plans the circuit again from the original ([`plan_circuit`], deterministic) to know where the
//! cavities and traces must be, and then looks only at the edited file:
//!
//! 1. **Lines**: every line of the original appears in the edited file unchanged and in order,
//!    except extruding moves replaced by cut pieces (motion lines, `G92`, `G10`/`G11` only); the
//!    other added lines are the summary (`; conduit postprocess: ...`), the inserted blocks
//!    (`; conduit: traces layer ...` / `; conduit: parts after layer ...` to `; conduit: end`)
//!    and OctoPNP's part description (`; conduit: OctoPNP part description` to
//!    `; conduit: end`, comment lines only).
//! 2. **Cavities**: replaying the edited file, no extruding move of a tool other than the
//!    conductive one has a point inside a layer's cuts (cavities and channels, shrunk by
//!    [`VerifyParams::tolerance`]), sampled every [`VerifyParams::sample_step`] along the move.
//! 3. **Traces**: every point of every planned trace is the end of a move of the conductive
//!    tool inside a block (tool offsets undone), and nothing else extrudes inside a block.
//! 4. **Events**: every part's event is in the file, after the host has printed a layer whose
//!    top reaches the top of the part's cavity.
//! 5. **OctoPNP**: with parts placed by the machine, one part description lists them all, in
//!    placement order, each with the id of its `M361 P<id>` and its destination at the part's
//!    position; without such parts there is none.
//! 6. **`conduit check`**: the edited file has no error-level finding.

use conduit_gcode::{Gcode, Line, LineEnding, Machine, Position};

use super::cut::CutRegion;
use super::plan::{CircuitPlan, plan_circuit};
use super::rewrite::{DESCRIPTION_MARK, END_MARK, PARTS_MARK, SUMMARY_PREFIX, TRACES_MARK};
use super::{PostprocessError, PostprocessParams, detect_host, read_layers};
use crate::check::check;
use crate::circuit::{Electronics, PlacingMethod};
use crate::geom::{Join, offset};
use crate::program::machine::Flavor;

/// How closely [`verify`] looks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifyParams {
    /// The cuts are shrunk by this before testing plastic against them, mm: the cut pieces'
    /// ends are written to 1 µm. Default 0.01.
    pub tolerance: f64,
    /// Spacing of the points tested along each extruding move, mm. Default 0.1.
    pub sample_step: f64,
    /// How far a written trace point may be from the planned one, mm. Default 0.002.
    pub trace_tolerance: f64,
    /// Problems listed per kind; the rest are counted. Default 10.
    pub max_listed: usize,
}

impl Default for VerifyParams {
    fn default() -> Self {
        Self {
            tolerance: 0.01,
            sample_step: 0.1,
            trace_tolerance: 0.002,
            max_listed: 10,
        }
    }
}

/// What [`verify`] found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VerifyReport {
    /// Lines of the original found unchanged in the edited file, in order.
    pub kept_lines: usize,
    /// Lines of the original replaced by cut pieces (1-based line numbers of the original).
    pub replaced_lines: Vec<usize>,
    /// Lines of cut pieces in the edited file.
    pub piece_lines: usize,
    /// Inserted blocks.
    pub blocks: usize,
    /// Lines of inserted blocks, markers included.
    pub block_lines: usize,
    /// Summary lines.
    pub summary_lines: usize,
    /// Lines of OctoPNP's part description, marks included.
    pub description_lines: usize,
    /// Parts listed in OctoPNP's part description, by name.
    pub described_parts: Vec<String>,
    /// Extruding moves of the host's tools that were tested against a layer's cuts.
    pub moves_tested: usize,
    /// Sampled points of host extrusion inside a cut (0 when the edit is right).
    pub plastic_in_cuts: usize,
    /// Moves of the conductive tool inside blocks.
    pub conductive_moves: usize,
    /// Planned trace points found as conductive moves.
    pub trace_points: usize,
    /// Part events found: part name and the highest host extrusion printed before it, mm.
    pub events: Vec<(String, f64)>,
    /// Error-level findings of `conduit check` on the edited file.
    pub check_errors: usize,
    /// Everything wrong, one line each; empty when the edit keeps its promises.
    pub problems: Vec<String>,
}

impl VerifyReport {
    /// True when no problem was found.
    pub fn is_ok(&self) -> bool {
        self.problems.is_empty()
    }
}

/// Checks `edited` against `original` for the circuit `electronics` built in with `params`
/// (those of the config `conduit postprocess` used: the host's settings, or the `-c` file;
/// `crate::config::Config::postprocess_params`), with the default [`VerifyParams`]. See the
/// [module docs](self) for what is checked.
///
/// # Errors
/// The errors of [`plan_circuit`] when the circuit cannot be planned on the original.
pub fn verify(
    original: &Gcode,
    edited: &Gcode,
    electronics: &Electronics,
    params: &PostprocessParams,
) -> Result<VerifyReport, PostprocessError> {
    verify_with(
        original,
        edited,
        electronics,
        params,
        &VerifyParams::default(),
    )
}

/// [`verify`] with explicit [`VerifyParams`].
///
/// # Errors
/// See [`verify`].
pub fn verify_with(
    original: &Gcode,
    edited: &Gcode,
    electronics: &Electronics,
    run: &PostprocessParams,
    params: &VerifyParams,
) -> Result<VerifyReport, PostprocessError> {
    let host = detect_host(original);
    let layer_params = run.layers.clone().for_host(host.host);
    let layers = read_layers(original, &host.markers, &layer_params);
    let plan = plan_circuit(&layers, electronics, &run.electronics)?;
    let flavor = run.gcode.printer.flavor;
    let mut report = VerifyReport::default();
    let mut problems = Problems::new(params.max_listed);
    let (blocks, descriptions) = match_lines(original, edited, flavor, &mut report, &mut problems);

    // Replay the edited file once; classify every move.
    let (block_points, events) = replay_edited(
        edited,
        &plan,
        &blocks,
        run,
        params,
        &mut report,
        &mut problems,
    );

    // Traces: every planned point is a conductive move's end.
    check_traces(
        &plan,
        &block_points,
        run,
        params,
        &mut report,
        &mut problems,
    );

    // Events: each part once, after its cavity is complete.
    check_events(&plan, &events, &mut problems);
    report.events = events.into_iter().map(|(n, z, _)| (n, z)).collect();

    // OctoPNP: the machine-placed parts described once, with their ids and destinations.
    check_description(&plan, edited, &descriptions, &mut report, &mut problems);

    check_findings(edited, run, &mut report, &mut problems);
    report.problems = problems.finish();
    Ok(report)
}

/// A part's event seen while replaying: the part's name, the host's top z so far, the line number.
type Event = (String, f64, usize);

/// Replays the edited file once, classifying every move: counts conductive moves inside blocks
/// (returning their ends, tool offsets undone), flags extrusion inside blocks and plastic inside
/// the cuts, and collects the events with the host's top z at the time.
fn replay_edited(
    edited: &Gcode,
    plan: &CircuitPlan,
    blocks: &[std::ops::Range<usize>],
    run: &PostprocessParams,
    params: &VerifyParams,
    report: &mut VerifyReport,
    problems: &mut Problems,
) -> (Vec<[f64; 2]>, Vec<Event>) {
    let flavor = run.gcode.printer.flavor;
    let conductive = run.electronics.conductive_tool;
    let offset_of = |tool: usize| run.gcode.tools.get(tool).map_or([0.0, 0.0], |t| t.offset);
    let regions: Vec<Option<CutRegion>> = plan
        .layers
        .iter()
        .map(|l| {
            (!l.cuts.is_empty())
                .then(|| CutRegion::new(&offset(&l.cuts, -params.tolerance, Join::Miter(2.0))))
        })
        .collect();
    let mut machine = Machine::new(flavor, 25.0);
    let mut block_points: Vec<[f64; 2]> = Vec::new();
    let mut host_top: f64 = f64::NEG_INFINITY;
    let mut events: Vec<Event> = Vec::new();
    let mut in_block = blocks.iter().peekable();
    for (i, line) in edited.lines.iter().enumerate() {
        while in_block.peek().is_some_and(|b| b.end <= i) {
            in_block.next();
        }
        let inside_block = in_block.peek().is_some_and(|b| b.contains(&i));
        if let Some(name) = event_part(line) {
            events.push((name, host_top, i + 1));
        }
        let Some(mv) = machine.step(line) else {
            continue;
        };
        if inside_block {
            if mv.tool == conductive {
                report.conductive_moves += 1;
                if let (Some(x), Some(y)) = (mv.to[0], mv.to[1]) {
                    let [dx, dy] = offset_of(conductive);
                    block_points.push([x + dx, y + dy]);
                }
            } else if mv.extruding {
                problems.push(
                    "block",
                    format!(
                        "line {}: tool {} extrudes inside a conduit block",
                        i + 1,
                        mv.tool
                    ),
                );
            }
            continue;
        }
        if !mv.extruding || mv.tool == conductive {
            continue;
        }
        let Some(z) = mv.to[2] else { continue };
        host_top = host_top.max(z);
        let Some(layer) = plan.zs.iter().position(|l| (l.top - z).abs() < 1e-3) else {
            continue;
        };
        let Some(Some(region)) = regions.get(layer) else {
            continue;
        };
        report.moves_tested += 1;
        let inside = samples(&mv.path, params.sample_step)
            .filter(|p| region.contains(*p))
            .count();
        if inside > 0 {
            report.plastic_in_cuts += inside;
            problems.push(
                "cavity",
                format!(
                    "line {}: tool {} extrudes inside a cavity or channel of layer {layer}",
                    i + 1,
                    mv.tool
                ),
            );
        }
    }
    (block_points, events)
}

/// Checks that every point of every planned trace is the end of a conductive move in a block.
fn check_traces(
    plan: &CircuitPlan,
    block_points: &[[f64; 2]],
    run: &PostprocessParams,
    params: &VerifyParams,
    report: &mut VerifyReport,
    problems: &mut Problems,
) {
    let conductive = run.electronics.conductive_tool;
    let tol2 = params.trace_tolerance * params.trace_tolerance;
    for (layer, p) in plan.layers.iter().enumerate() {
        for trace in &p.traces {
            for pt in &trace.points {
                let found = block_points
                    .iter()
                    .any(|q| (q[0] - pt.x).powi(2) + (q[1] - pt.y).powi(2) <= tol2);
                if found {
                    report.trace_points += 1;
                } else {
                    problems.push(
                        "trace",
                        format!(
                            "layer {layer}: trace point ({:.3}, {:.3}) is not printed by tool \
                             {conductive}",
                            pt.x, pt.y
                        ),
                    );
                }
            }
        }
    }
}

/// Checks that every part's event appears once, after the host has reached its cavity's top.
fn check_events(plan: &CircuitPlan, events: &[Event], problems: &mut Problems) {
    for part in &plan.parts {
        let top = part.position.z + part.body_height;
        let found: Vec<&Event> = events.iter().filter(|(n, _, _)| *n == part.name).collect();
        match found.as_slice() {
            [] => problems.push("event", format!("no event places part {}", part.name)),
            [(_, printed, line)] => {
                if *printed < top - 1e-6 {
                    problems.push(
                        "event",
                        format!(
                            "line {line}: part {} is placed when the print has reached z \
                             {printed:.3}, below its cavity's top {top:.3}",
                            part.name
                        ),
                    );
                }
            }
            _ => problems.push(
                "event",
                format!("part {} is placed {} times", part.name, found.len()),
            ),
        }
    }
}

/// Checks OctoPNP's part description: one block listing every part placed by the machine in
/// placement order, `id` its 1-based placement number (the `{id}` of its `M361 P<id>`), the
/// destination at the part's position (to the block's 4 decimals); none without such parts.
fn check_description(
    plan: &CircuitPlan,
    edited: &Gcode,
    descriptions: &[std::ops::Range<usize>],
    report: &mut VerifyReport,
    problems: &mut Problems,
) {
    let auto: Vec<(usize, &crate::circuit::PlacedPart)> = plan
        .parts
        .iter()
        .enumerate()
        .filter(|(_, p)| p.method == PlacingMethod::Auto)
        .map(|(i, p)| (i + 1, p))
        .collect();
    let block = match (descriptions, auto.is_empty()) {
        ([], true) => return,
        ([block], false) => block,
        (found, _) => {
            problems.push(
                "description",
                format!(
                    "{} OctoPNP part descriptions where {} expected ({} parts placed by the \
                     machine)",
                    found.len(),
                    if auto.is_empty() { "none is" } else { "one is" },
                    auto.len()
                ),
            );
            return;
        }
    };
    // The block's `<part id name>` lines, each with the `<destination>` that follows it.
    let mut described: Vec<(String, String, Option<[f64; 3]>)> = Vec::new();
    for line in edited.lines.get(block.clone()).unwrap_or_default() {
        let text = String::from_utf8_lossy(&line.text);
        let text = text.trim_start_matches(';').trim();
        if text.starts_with("<part ") {
            let id = xml_attr(text, "id").unwrap_or_default();
            let name = xml_attr(text, "name").unwrap_or_default();
            described.push((id, name, None));
        } else if text.starts_with("<destination ") {
            let xyz = ["x", "y", "z"].map(|k| xml_attr(text, k).and_then(|v| v.parse().ok()));
            if let (Some(last), [Some(x), Some(y), Some(z)]) = (described.last_mut(), xyz) {
                last.2 = Some([x, y, z]);
            }
        }
    }
    report.described_parts = described.iter().map(|(_, n, _)| n.clone()).collect();
    let want: Vec<(String, &str)> = auto
        .iter()
        .map(|(id, p)| (id.to_string(), p.name.as_str()))
        .collect();
    let got: Vec<(String, &str)> = described
        .iter()
        .map(|(id, n, _)| (id.clone(), n.as_str()))
        .collect();
    if want != got {
        problems.push(
            "description",
            format!(
                "OctoPNP's part description lists {got:?} (id, part), not the parts placed by \
                 the machine {want:?}"
            ),
        );
        return;
    }
    for ((_, part), (_, name, destination)) in auto.iter().zip(&described) {
        let p = [part.position.x, part.position.y, part.position.z];
        let off = destination.is_none_or(|d| d.iter().zip(p).any(|(a, b)| (a - b).abs() > 1e-3));
        if off {
            problems.push(
                "description",
                format!(
                    "OctoPNP's destination of part {name} is {destination:?}, not its position \
                     ({:.3}, {:.3}, {:.3})",
                    p[0], p[1], p[2]
                ),
            );
        }
    }
}

/// The value of the attribute `key` in an XML tag written as conduit writes it
/// (`key="value"`), unescaped.
fn xml_attr(tag: &str, key: &str) -> Option<String> {
    let start = tag.find(&format!(" {key}=\""))? + key.len() + 3;
    let len = tag.get(start..)?.find('"')?;
    let value = tag.get(start..start + len)?;
    Some(
        value
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&quot;", "\"")
            .replace("&amp;", "&"),
    )
}

/// Runs `conduit check` on the edited file and lists its error-level findings.
fn check_findings(
    edited: &Gcode,
    run: &PostprocessParams,
    report: &mut VerifyReport,
    problems: &mut Problems,
) {
    let checked = check(edited, &run.check);
    report.check_errors = checked.errors;
    for f in checked
        .findings
        .iter()
        .filter(|f| f.severity == crate::check::Severity::Error)
    {
        problems.push(
            "check",
            format!("conduit check: line {}: {}", f.line, f.message),
        );
    }
}

/// Problems, at most `max` listed per kind.
struct Problems {
    max: usize,
    listed: Vec<String>,
    counts: Vec<(&'static str, usize)>,
}

impl Problems {
    fn new(max: usize) -> Self {
        Self {
            max,
            listed: Vec::new(),
            counts: Vec::new(),
        }
    }

    fn push(&mut self, kind: &'static str, message: String) {
        let count = match self.counts.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, n)) => {
                *n += 1;
                *n
            }
            None => {
                self.counts.push((kind, 1));
                1
            }
        };
        if count <= self.max {
            self.listed.push(message);
        }
    }

    fn finish(mut self) -> Vec<String> {
        for (kind, n) in &self.counts {
            if *n > self.max {
                self.listed
                    .push(format!("... and {} more {kind} problems", n - self.max));
            }
        }
        self.listed
    }
}

/// The part an event line names: `;PICK_AND_PLACE PART=<name> ...`, `;MANUAL_INSERT
/// PART=<name>`, or the comment of a part that is not placed by the machine.
fn event_part(line: &Line) -> Option<String> {
    let text = line.comment_text()?;
    if let Some(event) = conduit_gcode::events::part_event(text, line.number) {
        return Some(event.part);
    }
    text.strip_prefix("part ")
        .and_then(|rest| rest.strip_suffix(" is not placed by the machine (method none)"))
        .map(str::to_owned)
}

/// Points every `step` mm along a replayed path (both ends included).
fn samples(path: &[Position], step: f64) -> impl Iterator<Item = [f64; 2]> + '_ {
    path.windows(2).flat_map(move |w| {
        let (a, b) = match (w[0], w[1]) {
            ([Some(ax), Some(ay), _], [Some(bx), Some(by), _]) => ([ax, ay], [bx, by]),
            _ => ([0.0; 2], [0.0; 2]),
        };
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = if step > 0.0 {
            ((len / step).ceil() as usize).max(1)
        } else {
            1
        };
        let known = w.iter().all(|p| p[0].is_some() && p[1].is_some());
        (0..=n).filter(move |_| known).map(move |k| {
            let t = k as f64 / n as f64;
            [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
        })
    })
}

/// Whether `line` may stand in a cut move's place: a `G0`/`G1` move, `G92`, `G10`/`G11`.
fn is_piece(line: &Line) -> bool {
    [(b'G', 0), (b'G', 1), (b'G', 92), (b'G', 10), (b'G', 11)]
        .iter()
        .any(|&(l, n)| line.is_command(l, n))
}

/// Whether two lines are the same line of the file: same bytes and ending (the original's last
/// line may have gained an ending when lines were added after it).
fn same(original: &Line, edited: &Line) -> bool {
    original.text == edited.text
        && (original.ending == edited.ending || original.ending == LineEnding::None)
}

/// How far ahead in the original a run of replaced moves may reach.
const LOOKAHEAD: usize = 256;

/// Line ranges of `edited`.
type Ranges = Vec<std::ops::Range<usize>>;

/// Matches the lines (step 1 of the [module docs](self)); returns the inserted blocks and
/// OctoPNP's part descriptions as line ranges of `edited`.
fn match_lines(
    original: &Gcode,
    edited: &Gcode,
    flavor: Flavor,
    report: &mut VerifyReport,
    problems: &mut Problems,
) -> (Ranges, Ranges) {
    let (orig, ed) = (&original.lines, &edited.lines);
    let mut machine = Machine::new(flavor, 25.0);
    let extruding: Vec<bool> = orig
        .iter()
        .map(|l| machine.step(l).is_some_and(|m| m.extruding))
        .collect();
    let is_block_start = |l: &Line| {
        let t = String::from_utf8_lossy(&l.text);
        t.starts_with(TRACES_MARK) || t.starts_with(PARTS_MARK)
    };
    let mut blocks = Vec::new();
    let mut descriptions = Vec::new();
    let (mut i, mut j) = (0, 0);
    // The first original line at or after `i` (over extruding moves only) that `ed[j]` is.
    let ahead = |i: usize, j: usize| -> Option<usize> {
        let line = ed.get(j)?;
        let mut k = i;
        while k < orig.len() && k < i + LOOKAHEAD {
            if same(&orig[k], line) {
                return Some(k);
            }
            if !extruding[k] {
                return None;
            }
            k += 1;
        }
        None
    };
    while j < ed.len() {
        let line = &ed[j];
        if line.text.starts_with(SUMMARY_PREFIX.as_bytes()) {
            report.summary_lines += 1;
            j += 1;
            continue;
        }
        if line.text == DESCRIPTION_MARK.as_bytes() {
            // Comment lines only, up to the end mark.
            let comment_only = |l: &Line| l.comment.is_some() && l.words.is_empty();
            let end = (j + 1..ed.len())
                .find(|&k| ed[k].text == END_MARK.as_bytes() || !comment_only(&ed[k]));
            let Some(end) = end.filter(|&k| ed[k].text == END_MARK.as_bytes()) else {
                problems.push(
                    "lines",
                    format!(
                        "line {}: OctoPNP part description without `{END_MARK}` after its \
                         comment lines",
                        j + 1
                    ),
                );
                return (blocks, descriptions);
            };
            report.description_lines += end + 1 - j;
            descriptions.push(j..end + 1);
            j = end + 1;
            continue;
        }
        if is_block_start(line) {
            let Some(end) = (j..ed.len()).find(|&k| ed[k].text == END_MARK.as_bytes()) else {
                problems.push(
                    "lines",
                    format!("line {}: block without `{END_MARK}`", j + 1),
                );
                return (blocks, descriptions);
            };
            report.blocks += 1;
            report.block_lines += end + 1 - j;
            blocks.push(j..end + 1);
            j = end + 1;
            continue;
        }
        if i < orig.len() && same(&orig[i], line) {
            report.kept_lines += 1;
            i += 1;
            j += 1;
            continue;
        }
        if i >= orig.len() {
            problems.push(
                "lines",
                format!("line {}: added after the end of the original", j + 1),
            );
            return (blocks, descriptions);
        }
        if !extruding[i] {
            problems.push(
                "lines",
                format!(
                    "original line {} ({}) is missing or changed (edited line {})",
                    i + 1,
                    String::from_utf8_lossy(&orig[i].text),
                    j + 1
                ),
            );
            return (blocks, descriptions);
        }
        // orig[i] was cut: the pieces run until the file meets the original again.
        report.replaced_lines.push(i + 1);
        i += 1;
        while j < ed.len() && is_piece(&ed[j]) && ahead(i, j).is_none() {
            report.piece_lines += 1;
            j += 1;
        }
        match ahead(i, j) {
            // Further moves of the original were cut too (their pieces were just consumed).
            Some(k) => {
                report.replaced_lines.extend(i + 1..=k);
                i = k;
            }
            None if j >= ed.len()
                || is_block_start(&ed[j])
                || ed[j].text == DESCRIPTION_MARK.as_bytes() => {}
            None => {
                problems.push(
                    "lines",
                    format!(
                        "edited line {} ({}) is neither a line of the original nor conduit's",
                        j + 1,
                        String::from_utf8_lossy(&ed[j].text)
                    ),
                );
                return (blocks, descriptions);
            }
        }
    }
    if i < orig.len() {
        problems.push(
            "lines",
            format!(
                "original lines {} to {} are missing at the end",
                i + 1,
                orig.len()
            ),
        );
    }
    (blocks, descriptions)
}
