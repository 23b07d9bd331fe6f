//! The wipe tower end to end: two boxes printed by two filament tools (the lower one ends the
//! tool changes at its top), sliced by the binary with `[wipe_tower]` on, the G-code replayed
//! with `conduit_gcode` and checked: every change to a tool is followed by its purge on the
//! tower of at least the volume asked, the tower stands in one place from the first layer to the
//! last change and no higher, apart from the boxes, and `conduit check` finds nothing wrong.

use std::path::Path;

use conduit::geom::Point3;
use conduit_gcode::{Firmware, Move, Moves, moves};

use crate::support::{conduit, stdout, temp_dir, write_stl, xyz};

/// A closed box from `lo` to `hi`, outward-facing.
fn boxed(lo: [f64; 3], hi: [f64; 3]) -> Vec<[Point3; 3]> {
    let c = |i: usize| {
        Point3::new(
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        )
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

/// Two filament tools, the tower on with a 100 mm³ purge.
const CONFIG: &str = "[tools.0]\nkind = \"filament\"\n[tools.1]\nkind = \"filament\"\n\
                      [slice]\nobject_tools = [0, 1]\n\
                      [wipe_tower]\nenabled = true\npurge_volume = 100.0\n";

/// The boxes: 10 × 10 × 4 mm with tool 0, beside it 10 × 10 × 2 mm with tool 1.
fn slice(dir: &Path, extra: &[&str]) -> (std::process::Output, serde_json::Value) {
    let (a, b) = (dir.join("a.stl"), dir.join("b.stl"));
    write_stl(&a, &boxed([0.0, 0.0, 0.0], [10.0, 10.0, 4.0]));
    write_stl(&b, &boxed([15.0, 0.0, 0.0], [25.0, 10.0, 2.0]));
    let cfg = dir.join("two.toml");
    std::fs::write(&cfg, CONFIG).expect("config written");
    let mut args: Vec<String> = [
        "slice",
        &a.display().to_string(),
        &b.display().to_string(),
        "-c",
        &cfg.display().to_string(),
        "-o",
        &dir.join("out.gcode").display().to_string(),
        "--report",
        &dir.join("out.json").display().to_string(),
    ]
    .map(str::to_owned)
    .to_vec();
    args.extend(extra.iter().map(|s| (*s).to_owned()));
    let out = conduit(&args);
    let report = std::fs::read_to_string(dir.join("out.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(serde_json::Value::Null);
    (out, report)
}

/// [`slice`], which must succeed, and its G-code replayed (Marlin), with the report.
fn sliced(dir: &Path, extra: &[&str]) -> (Moves, serde_json::Value) {
    let (out, report) = slice(dir, extra);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.join("out.gcode")).expect("G-code");
    let g = conduit_gcode::parse(text.as_bytes()).expect("G-code parses");
    (moves(&g, Firmware::Marlin), report)
}

/// The box `[min x, min y, max x, max y]` round the extruding moves that `pick` keeps.
fn extent(replay: &Moves, pick: &dyn Fn(&Move) -> bool) -> [f64; 4] {
    let mut b = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
    for m in replay
        .moves
        .iter()
        .filter(|m| m.extruding && m.has_xy && pick(m))
    {
        for p in [xyz(m.from), xyz(m.to)] {
            b = [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ];
        }
    }
    b
}

/// `conduit check` replays `dir/out.gcode` with the two-tool config without an error or a
/// warning (no extrusion into air).
fn check_is_clean(dir: &Path) {
    let check = conduit([
        "check".as_ref(),
        dir.join("out.gcode").as_os_str(),
        "-c".as_ref(),
        dir.join("two.toml").as_os_str(),
    ]);
    let said = stdout(&check);
    assert!(
        check.status.success() && said.contains("0 errors, 0 warnings"),
        "{said}"
    );
}

#[test]
fn every_tool_change_purges_on_one_tower_standing_up_to_the_last_change() {
    let dir = temp_dir();
    let dir = dir.path();
    // Without the first layer's brim (its own test below), every purge is the new tool's first
    // extrusion.
    let (replay, report) = sliced(dir, &["--set", "wipe_tower.brim_width=0"]);
    let filament = std::f64::consts::PI * 1.75f64.powi(2) / 4.0;
    let is_tower = |m: &Move| m.role.as_deref() == Some("Wipe tower");

    // The purges: after each change, the extrusion up to the next role is the tower's, by the
    // new tool, and holds at least 100 mm³.
    let mut purges = Vec::new();
    let mut since_change: Option<(usize, f64, bool)> = None;
    let mut tool = 0;
    for m in &replay.moves {
        if m.tool != tool {
            if let Some(p) = since_change.take() {
                purges.push(p);
            }
            tool = m.tool;
            since_change = Some((tool, 0.0, true));
        }
        if m.extruding && m.has_xy {
            match &mut since_change {
                Some((_, volume, open)) if *open && is_tower(m) => *volume += m.e * filament,
                Some((_, _, open)) => *open = false,
                None => {}
            }
        }
    }
    purges.extend(since_change);
    // 0.2 mm layers: the 2 mm box ends at layer 9, and the tools alternate one change a layer.
    assert_eq!(purges.len(), 10, "{purges:?}");
    for (n, (tool, volume, _)) in purges.iter().enumerate() {
        assert_eq!(*tool, (n + 1) % 2);
        assert!((100.0..110.0).contains(volume), "purge {n}: {volume} mm³");
    }

    // The tower: one box on the bed, on layers 0..=9 only, apart from the boxes' paths.
    let layers_of = |pick: &dyn Fn(&Move) -> bool| -> Vec<usize> {
        let mut v: Vec<usize> = replay
            .moves
            .iter()
            .filter(|m| m.extruding && m.has_xy && pick(m))
            .map(|m| m.layer)
            .collect();
        v.dedup();
        v
    };
    assert_eq!(layers_of(&is_tower), (0..10).collect::<Vec<_>>());
    let tower = extent(&replay, &is_tower);
    let parts = extent(&replay, &|m| {
        !is_tower(m) && m.role.as_deref().is_none_or(|r| r != "Skirt/Brim")
    });
    let t = &report["wipe_tower"];
    let num = |k: &str| t[k].as_f64().expect(k);
    // Bead centres lie half a bead inside the tower's outline.
    let (x, y, w, d) = (num("x"), num("y"), num("width"), num("depth"));
    for (got, want) in tower
        .iter()
        .zip([x + 0.225, y + 0.225, x + w - 0.225, y + d - 0.225])
    {
        assert!((got - want).abs() < 2e-3, "tower {tower:?} against {t}");
    }
    assert!(
        tower[0] >= parts[2] + 5.0 - 0.25,
        "tower {tower:?}, parts {parts:?}"
    );
    assert_eq!(t["layers"], 10);
    assert_eq!(t["purges"], 10);
    check_is_clean(dir);
}

#[test]
fn a_tower_set_over_the_parts_is_refused_and_nothing_is_written() {
    let dir = temp_dir();
    let dir = dir.path();
    // The boxes are centred on the 250 mm bed, about X 112–138, Y 120–130.
    let (out, _) = slice(
        dir,
        &["--set", "wipe_tower.x=100", "--set", "wipe_tower.y=115"],
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("the wipe tower at x 100, y 115") && err.contains("overlaps"),
        "{err}"
    );
    assert!(!dir.join("out.gcode").exists());
}

/// The tower's first layer has a brim of whole beads round it (2 mm asked: 4 beads of 0.45),
/// laid by the first tool on the tower, 5 mm clear of the parts; the layers above have none.
#[test]
fn the_towers_first_layer_stands_on_a_brim() {
    let dir = temp_dir();
    let dir = dir.path();
    let (replay, report) = sliced(dir, &[]);
    let t = &report["wipe_tower"];
    let num = |k: &str| t[k].as_f64().expect(k);
    assert!((num("brim_width") - 1.8).abs() < 1e-9, "{t}");
    let bounds = |layer: usize, tower: bool| {
        extent(&replay, &|m| {
            m.layer == layer && (m.role.as_deref() == Some("Wipe tower")) == tower
        })
    };
    let (first, second) = (bounds(0, true), bounds(1, true));
    // The outermost brim bead's centre lies 3.5 beads outside the tower's outline, the loop's
    // half a bead inside it: the first layer's extent is the second's grown by 4 beads.
    for (k, sign) in [-1.0, -1.0, 1.0, 1.0].into_iter().enumerate() {
        let grown = second[k] + sign * 1.8;
        assert!(
            (first[k] - grown).abs() < 2e-3,
            "first layer {first:?}, second {second:?}"
        );
    }
    // The brim's outer edge (half a bead beyond the outermost centre) stays 5 mm clear of the
    // parts' paths on the first layer.
    let parts = bounds(0, false);
    assert!(
        first[0] - 0.225 >= parts[2] + 0.225 + 5.0 - 1e-3,
        "tower {first:?}, parts {parts:?}"
    );
    check_is_clean(dir);
}
