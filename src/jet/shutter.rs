//! The jet's G-code: travels with the shutter closed, the shutter opened and closed around
//! every path by the `[jet]` snippets, fillets as `G2`/`G3` arcs or chords.
//!
//! Place in the pipeline: schedule → **shutter** (emit) → file.
//!
//! The project's G-code writer ([`crate::emit::gcode`]) switches paste tools with their
//! `paste_on_gcode`/`paste_off_gcode` and writes their moves without `E`, so `conduit check` and
//! `conduit preview` would see no printing; it also has no arcs and no shutter lead. This
//! writer keeps the project's conventions instead (one number formatter: XYZ 3 decimals, E 5,
//! F integer; PrusaSlicer's `;LAYER_CHANGE`, `;Z:`, `;HEIGHT:`, `;TYPE:`, `;WIDTH:` markers;
//! a [`GcodeSink`]) and writes:
//!
//! - a header (`; conduit <version>`, flavour, layer count), `G21`, `G90`, `M83`,
//!   `jet.start_gcode`, the shutter closed, `T<jet.tool>`;
//! - per layer the markers and `G1 Z<z>` (shutter closed);
//! - per path: a travel `G1 X Y F<travel_speed>` to the start, the open snippet, the path at
//!   `jet.speed` (`G1`, and `G2`/`G3 X Y I J` for fillets when `jet.arcs`), the close snippet.
//!   With `jet.e_words` every printing move carries `E` = its length in mm (relative), so
//!   replays count it as printing.
//! - With `jet.shutter_lead_time = t > 0` (shutter on the fly) the travel stops `t·speed`
//!   before the start on the path's starting tangent, the shutter opens there and the nozzle
//!   runs on to the start at `jet.speed` (without `E`: nothing lands yet); the close snippet is
//!   written `t·speed` before the path's end, and the path is finished before the travel.
//! - at the end the shutter closed and `jet.end_gcode`.

use conduit_gcode::{fmt_e, fmt_f, fmt_xyz};
use serde::Serialize;

use super::JetSettings;
use super::path::{Chain, Seg};
use super::schedule::JetLayer;
use crate::emit::gcode::GcodeSink;
use crate::program::machine::Flavor;

/// What the writer wrote.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct JetStats {
    /// Paths printed (shutter cycles).
    pub paths: usize,
    /// Jetted length, mm.
    pub jetted_mm: f64,
    /// Travel length, mm (XY).
    pub travel_mm: f64,
    /// Estimated time at the set speeds (no acceleration), s.
    pub estimated_time_s: f64,
}

struct W<'a, S: GcodeSink> {
    jet: &'a JetSettings,
    sink: &'a mut S,
    /// Position as written (XY), when known.
    pos: Option<[f64; 2]>,
    /// Written XY strings of `pos`.
    pos_str: Option<(String, String)>,
    feed: Option<String>,
    type_name: Option<&'static str>,
    width: Option<String>,
    /// E carried from moves too short to write.
    pending_e: f64,
    stats: JetStats,
}

fn snippet_lines(text: &str) -> impl Iterator<Item = &str> {
    text.lines()
        .map(str::trim_end)
        .filter(|l| !l.trim().is_empty())
}

impl<S: GcodeSink> W<'_, S> {
    fn line(&mut self, l: &str) {
        self.sink.line(l);
    }

    fn snippet(&mut self, text: &str) {
        for l in snippet_lines(text) {
            self.sink.line(l);
        }
    }

    fn feed_word(&mut self, mm_s: f64) -> String {
        let f = fmt_f(mm_s * 60.0);
        if self.feed.as_deref() == Some(f.as_str()) {
            String::new()
        } else {
            self.feed = Some(f.clone());
            format!(" F{f}")
        }
    }

    fn same_xy(&self, p: [f64; 2]) -> bool {
        self.pos_str
            .as_ref()
            .is_some_and(|(x, y)| *x == fmt_xyz(p[0]) && *y == fmt_xyz(p[1]))
    }

    fn set_pos(&mut self, p: [f64; 2]) {
        self.pos = Some(p);
        self.pos_str = Some((fmt_xyz(p[0]), fmt_xyz(p[1])));
    }

    fn travel(&mut self, p: [f64; 2]) {
        if self.same_xy(p) {
            return;
        }
        let s = self.jet.travel_speed;
        if let Some(from) = self.pos {
            let d = (p[0] - from[0]).hypot(p[1] - from[1]);
            self.stats.travel_mm += d;
            self.stats.estimated_time_s += d / s;
        }
        let f = self.feed_word(s);
        self.line(&format!("G1 X{} Y{}{f}", fmt_xyz(p[0]), fmt_xyz(p[1])));
        self.set_pos(p);
    }

    /// A printing move along `seg` (with `E` when `with_e`).
    fn print(&mut self, seg: &Seg, with_e: bool) {
        let jet = self.jet;
        let len = seg.length();
        self.stats.jetted_mm += if with_e { len } else { 0.0 };
        self.stats.estimated_time_s += len / jet.speed;
        let e_on = jet.e_words && with_e;
        match *seg {
            Seg::Arc { a, b, c, sweep, .. } if jet.arcs => {
                if self.same_xy(b) {
                    self.pending_e += len;
                    return;
                }
                let cmd = if sweep > 0.0 { "G3" } else { "G2" };
                let e = if e_on {
                    format!(" E{}", fmt_e(len + self.pending_e))
                } else {
                    String::new()
                };
                self.pending_e = 0.0;
                // I and J from the written start, so the firmware's centre is the true one
                // within the output resolution.
                let from = self.pos.unwrap_or(a);
                let f = self.feed_word(jet.speed);
                self.line(&format!(
                    "{cmd} X{} Y{} I{} J{}{e}{f}",
                    fmt_xyz(b[0]),
                    fmt_xyz(b[1]),
                    fmt_xyz(c[0] - from[0]),
                    fmt_xyz(c[1] - from[1])
                ));
                self.set_pos(b);
            }
            _ => {
                let tol = jet.arc_tolerance;
                let mut prev = seg.start();
                for p in seg.flatten(tol) {
                    let d = (p[0] - prev[0]).hypot(p[1] - prev[1]);
                    prev = p;
                    if self.same_xy(p) {
                        self.pending_e += d;
                        continue;
                    }
                    let e = if e_on {
                        format!(" E{}", fmt_e(d + self.pending_e))
                    } else {
                        String::new()
                    };
                    self.pending_e = 0.0;
                    let f = self.feed_word(self.jet.speed);
                    self.line(&format!("G1 X{} Y{}{e}{f}", fmt_xyz(p[0]), fmt_xyz(p[1])));
                    self.set_pos(p);
                }
            }
        }
    }

    fn path(&mut self, chain: &Chain, fill: bool, width: f64) {
        let (Some(start), Some(first)) = (chain.start(), chain.segs.first()) else {
            return;
        };
        let jet = self.jet;
        let type_name = if fill { "Jet fill" } else { "Jet wall" };
        if self.type_name != Some(type_name) {
            self.line(&format!(";TYPE:{type_name}"));
            self.type_name = Some(type_name);
        }
        let w = fmt_xyz(width);
        if self.width.as_deref() != Some(w.as_str()) {
            self.line(&format!(";WIDTH:{w}"));
            self.width = Some(w);
        }
        let lead = jet.shutter_lead_time * jet.speed;
        let (open, close) = (
            jet.shutter_open_gcode.clone(),
            jet.shutter_close_gcode.clone(),
        );
        self.pending_e = 0.0;
        if lead > 0.0 {
            let d = first.start_direction();
            let approach = [start[0] - d[0] * lead, start[1] - d[1] * lead];
            self.travel(approach);
            self.snippet(&open);
            self.line("; shutter lead-in");
            self.print(
                &Seg::Line {
                    a: approach,
                    b: start,
                },
                false,
            );
        } else {
            self.travel(start);
            self.snippet(&open);
        }
        self.stats.paths += 1;
        let total = chain.length();
        let (body, tail) = if lead > 0.0 {
            chain.split_at((total - lead).max(0.0))
        } else {
            (chain.clone(), Chain::default())
        };
        for seg in &body.segs {
            self.print(seg, true);
        }
        self.snippet(&close);
        for seg in &tail.segs {
            self.print(seg, true);
        }
    }
}

/// Writes the whole job for `layers` with line `width` (mm), the `[jet]` settings and the
/// printer's firmware `flavor`, to `sink`.
pub fn write_jet<S: GcodeSink>(
    layers: &[JetLayer],
    width: f64,
    (jet, flavor): (&JetSettings, Flavor),
    sink: &mut S,
) -> JetStats {
    let version = env!("CARGO_PKG_VERSION");
    let mut w = W {
        jet,
        sink,
        pos: None,
        pos_str: None,
        feed: None,
        type_name: None,
        width: None,
        pending_e: 0.0,
        stats: JetStats::default(),
    };
    w.line(&format!("; conduit {version}"));
    w.line(&format!("; generated by conduit {version} (jet)"));
    w.line(&format!("; flavor = {flavor}"));
    w.line(&format!("; layer count = {}", layers.len()));
    w.line(&format!(
        "; jet: tool {}, line width {} mm, arcs {}, shutter lead {} s",
        jet.tool,
        fmt_xyz(width),
        if jet.arcs { "G2/G3" } else { "flattened" },
        fmt_e(jet.shutter_lead_time)
    ));
    w.line("");
    w.line("G21");
    w.line("G90");
    w.line("M83");
    w.snippet(&jet.start_gcode);
    w.snippet(&jet.shutter_close_gcode);
    w.line(&format!("T{}", jet.tool));
    for layer in layers {
        w.line(";LAYER_CHANGE");
        w.line(&format!(";Z:{}", fmt_xyz(layer.z)));
        w.line(&format!(";HEIGHT:{}", fmt_xyz(layer.height)));
        let f = w.feed_word(jet.travel_speed);
        w.line(&format!("G1 Z{}{f}", fmt_xyz(layer.z)));
        for p in &layer.paths {
            w.path(&p.chain, p.fill, width);
        }
    }
    w.line(";TYPE:Custom");
    w.snippet(&jet.shutter_close_gcode);
    w.snippet(&jet.end_gcode);
    w.stats
}
