use super::*;

fn rec(reference: &str, value: &str, package: &str, xyzr: [f64; 4], side: Side) -> PlacementRecord {
    let [x, y, z, rotation_deg] = xyzr;
    let (reference, value, package) = (reference.into(), value.into(), package.into());
    PlacementRecord {
        reference,
        value,
        package,
        x,
        y,
        z,
        rotation_deg,
        side,
        enabled: true,
        height: 0.0,
    }
}

/// The 2-record example of the exact-text tests: a comma, quotes, `<`, `>` and `&` in strings,
/// a value needing rounding and a negative rotation.
fn example() -> Vec<PlacementRecord> {
    vec![
        rec(
            "R1",
            "10k, 1%",
            "R_0603",
            [10.0, -5.25, 0.0, 90.0],
            Side::Top,
        ),
        rec(
            "U\"2",
            "<TL072> & co",
            "SOIC-8",
            [1.23456, 2.0, 1.6, -90.0],
            Side::Bottom,
        ),
    ]
    .into_iter()
    .map(|r| PlacementRecord {
        height: if r.side == Side::Bottom { 1.5 } else { 0.0 },
        ..r
    })
    .collect()
}

fn kicad(records: &[PlacementRecord]) -> String {
    let mut out = Vec::new();
    write_kicad_csv(records, &mut out).expect("writing to a Vec");
    String::from_utf8(out).expect("UTF-8")
}

fn kicad_ascii(records: &[PlacementRecord]) -> String {
    let mut out = Vec::new();
    write_kicad_ascii(records, &mut out).expect("writing to a Vec");
    String::from_utf8(out).expect("UTF-8")
}

fn openpnp(records: &[PlacementRecord]) -> String {
    let mut out = Vec::new();
    write_openpnp_board("demo & <test>", records, &mut out).expect("writing to a Vec");
    String::from_utf8(out).expect("UTF-8")
}

#[test]
fn kicad_exact_text() {
    let expected = r#"Ref,Val,Package,PosX,PosY,Rot,Side
"R1","10k, 1%","R_0603",10.000000,-5.250000,90.000000,top
"U""2","<TL072> & co","SOIC-8",1.234560,2.000000,-90.000000,bottom
"#;
    assert_eq!(kicad(&example()), expected);
}

#[test]
fn kicad_ascii_exact_text() {
    let mut records = example();
    records.push(rec(
        "R10",
        "4k7",
        "R_0603_1608Metric_Pad0.98x0.95mm",
        [-123.456789, 7.0, 0.0, 180.0],
        Side::Top,
    ));
    records.push(rec(
        "R2",
        "1 k",
        "R 0603",
        [1.0, 2.0, 0.0, 540.0],
        Side::Top,
    ));
    records.push(PlacementRecord {
        enabled: false,
        ..rec("BAT1", "CR2032", "HOLDER", [0.0; 4], Side::Top)
    });
    let version = env!("CARGO_PKG_VERSION");
    let expected = format!(
        "### Footprint positions - created by conduit ###\n\
         ### Printed by conduit version {version}\n\
         ## Unit = mm, Angle = deg.\n\
         ## Side : All\n\
         # Ref     Val           Package                                PosX       PosY       Rot  Side\n\
         R1        10k,_1%       R_0603                              10.0000    -5.2500   90.0000  top\n\
         R2        1_k           R_0603                               1.0000     2.0000  180.0000  top\n\
         R10       4k7           R_0603_1608Metric_Pad0.98x0.95mm  -123.4568     7.0000  180.0000  top\n\
         U\"2       <TL072>_&_co  SOIC-8                               1.2346     2.0000  -90.0000  bottom\n\
         ## End\n"
    );
    assert_eq!(kicad_ascii(&records), expected);
}

#[test]
fn every_ascii_row_matches_the_openpnp_importer_pattern() {
    let mut records = example();
    records.push(rec("LED1", "", "LED_0805", [1.0, 2.0, 3.0, 0.0], Side::Top));
    let read = read_kicad_ascii(&kicad_ascii(&records)).expect("importer pattern");
    let got: Vec<(&str, &str, &str, f64, f64, f64, Side)> = read
        .iter()
        .map(|r| {
            let (a, b, c) = (r.reference.as_str(), r.value.as_str(), r.package.as_str());
            (a, b, c, r.x, r.y, r.rotation_deg, r.side)
        })
        .collect();
    assert_eq!(
        got,
        [
            ("LED1", "~", "LED_0805", 1.0, 2.0, 0.0, Side::Top),
            ("R1", "10k,_1%", "R_0603", 10.0, -5.25, 90.0, Side::Top),
            (
                "U\"2",
                "<TL072>_&_co",
                "SOIC-8",
                1.2346,
                2.0,
                -90.0,
                Side::Bottom
            ),
        ]
    );
    // What the importer refuses, the mirror refuses: an exponent, a missing column.
    for bad in ["R1 1k R 1e3 2.0 0.0 top", "R1 1k 1.0 2.0 top"] {
        let err = read_kicad_ascii(bad).expect_err(bad);
        assert!(
            err.to_string().starts_with("line 1: not a position row"),
            "{err}"
        );
    }
}

#[test]
fn openpnp_exact_text() {
    let expected = r#"<openpnp-board version="1.1" name="demo &amp; &lt;test&gt;">
   <!-- Locations are in the printer's bed coordinates, mm: put the board at X 0, Y 0, Z 0, rotation 0 in the job. z is each part's seating plane (0 on a flat board, higher inside a printed object). -->
   <placements>
      <!-- R1: height 0.0000 mm -->
      <placement version="1.4" id="R1" side="Top" part-id="R_0603-10k, 1%" type="Placement" enabled="true">
         <location units="Millimeters" x="10.0000" y="-5.2500" z="0.0000" rotation="90.0000"/>
      </placement>
      <!-- U"2: height 1.5000 mm -->
      <placement version="1.4" id="U&quot;2" side="Bottom" part-id="SOIC-8-&lt;TL072&gt; &amp; co" type="Placement" enabled="true">
         <location units="Millimeters" x="1.2346" y="2.0000" z="1.6000" rotation="270.0000"/>
      </placement>
   </placements>
</openpnp-board>
"#;
    assert_eq!(openpnp(&example()), expected);
}

#[test]
fn round_trips_up_to_rounding() {
    let mut records = example();
    records.push(rec(
        "a,b\n\"c\"\td",
        "x&y",
        "P<1>",
        [-0.00001, 1e3 / 3.0, -2.5, 719.99],
        Side::Top,
    ));
    // What the OpenPnP writer promises: 4 decimals, rotation in [0, 360), file order.
    let round = |v: f64| (v * 1e4).round() / 1e4;
    let expected: Vec<_> = records
        .iter()
        .map(|r| PlacementRecord {
            x: round(r.x),
            y: round(r.y),
            z: round(r.z),
            rotation_deg: round(r.rotation_deg.rem_euclid(360.0)),
            ..r.clone()
        })
        .collect();
    let from_openpnp = read_openpnp_board(&openpnp(&records)).expect("own XML reads back");
    for read in [&from_openpnp] {
        assert_eq!(read.len(), records.len());
        for ((got, want), orig) in read.iter().zip(&expected).zip(&records) {
            assert_eq!(got.x.abs(), want.x.abs(), "{got:?}"); // -0.0 is written as 0.0000
            assert_eq!(
                (got.y, got.z, got.rotation_deg),
                (want.y, want.z, want.rotation_deg)
            );
            assert!((got.y - orig.y).abs() <= 5e-5 && (got.z - orig.z).abs() <= 5e-5);
            assert_eq!(
                (&got.reference, &got.value, &got.package),
                (&want.reference, &want.value, &want.package)
            );
            assert_eq!(got.side, want.side);
        }
    }
}

#[test]
fn output_is_deterministic_and_normalised() {
    assert_eq!(kicad(&example()), kicad(&example()));
    let r = [rec(
        "R",
        "",
        "P",
        [-0.0000001, 0.0, 0.0, 359.9999999],
        Side::Top,
    )];
    assert!(kicad(&r).ends_with("\n\"R\",\"\",\"P\",0.000000,0.000000,0.000000,top\n"));
    for bad in [f64::NAN, f64::INFINITY] {
        let r = [rec("R", "", "P", [bad, 0.0, 0.0, 0.0], Side::Top)];
        let mut out = Vec::new();
        let err = write_kicad_csv(&r, &mut out).expect_err("non-finite x");
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(out.is_empty());
        let err = write_kicad_ascii(&r, &mut out).expect_err("non-finite x");
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(out.is_empty());
        let err = write_openpnp_board("b", &r, &mut out).expect_err("non-finite x");
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
    }
    let r = [rec("R\u{1}", "", "P", [0.0; 4], Side::Top)];
    assert!(write_openpnp_board("b", &r, &mut Vec::new()).is_err());
}

#[test]
fn reads_kicads_own_csv() {
    // pcbnew's CSV: 6 decimals, -180..180 rotation, no PosZ; here with CRLF and a blank line.
    let text = "Ref,Val,Package,PosX,PosY,Rot,Side\r\n\
                \"C1\",\"100n\",\"C_0603\",120.650000,-80.010000,-90.000000,bottom\r\n\r\n";
    let got = read_kicad_csv(text).expect("KiCad CSV");
    assert_eq!(
        got,
        [rec(
            "C1",
            "100n",
            "C_0603",
            [120.65, -80.01, 0.0, -90.0],
            Side::Bottom
        )]
    );
}

#[test]
fn malformed_csv_errors_name_the_line() {
    let head = "Ref,Val,Package,PosX,PosY,Rot,Side,PosZ\n\"R1\",\"1k\",\"R\",1,2,0,top,0\n";
    let cases = [
        (
            "\"R2\",\"1k\",\"R\",1,x,0,top,0\n",
            "line 3: column PosY: invalid value `x`",
        ),
        (
            "\"R2\",\"1k\",\"R\",1,2,0,middle,0\n",
            "line 3: column Side: invalid value `middle`",
        ),
        (
            "\"R2\",\"1k\",\"R\",1,2,0,top,NaN\n",
            "line 3: column PosZ: invalid value `NaN`",
        ),
        (
            "\"R2\",\"1k\",\"R\",1,2,0,top\n",
            "line 3: expected 8 fields, found 7",
        ),
        ("\n\"R2\",\"1k\n", "line 4: quoted field is never closed"),
    ];
    for (tail, message) in cases {
        let err = read_kicad_csv(&format!("{head}{tail}")).expect_err(tail);
        assert_eq!(err.to_string(), message);
    }
    let err = read_kicad_csv("\n\nRef;Val\n").expect_err("bad header");
    assert!(
        err.to_string().starts_with("line 3: expected header"),
        "{err}"
    );
    assert!(matches!(
        read_kicad_csv(""),
        Err(PnpError::CsvHeader { line: 1, .. })
    ));
}

#[test]
fn reads_openpnp_files_skipping_fiducials_and_flagging_what_it_would_not_place() {
    let text = r#"<openpnp-board name="old">
   <dimensions units="Millimeters" x="37.0" y="0.0" z="0.0" rotation="0.0"/>
   <fiducials/>
   <placements>
      <placement version="1.1" id="R1" side="Top" part-id="SOT-23-BC847" type="Place">
         <location units="Inches" x="1.0" y="0.5" rotation="45.0"/>
      </placement>
      <placement version="1.1" id="R7" side="Top" part-id="R0201-1K" type="Ignore">
         <location units="Millimeters" x="12.0" y="22.0" z="0.0" rotation="315.0"/>
      </placement>
      <placement version="1.4" id="FID1" side="Top" type="Fiducial"><location units="Millimeters"/></placement>
      <placement version="1.4" id="R9" side="Top" part-id="R" type="Placement" enabled="false"><location units="Millimeters"/></placement>
   </placements>
   <solder-paste-pads>
      <board-pad type="Paste" side="Top" name="R1-1"><location units="Millimeters" x="3"/></board-pad>
   </solder-paste-pads>
</openpnp-board>
"#;
    let got = read_openpnp_board(text).expect("OpenPnP board");
    let disabled = |r: PlacementRecord| PlacementRecord {
        enabled: false,
        ..r
    };
    assert_eq!(
        got,
        [
            rec("R1", "BC847", "SOT-23", [25.4, 12.7, 0.0, 45.0], Side::Top),
            disabled(rec(
                "R7",
                "1K",
                "R0201",
                [12.0, 22.0, 0.0, 315.0],
                Side::Top
            )),
            disabled(rec("R9", "", "R", [0.0; 4], Side::Top)),
        ]
    );
}

#[test]
fn malformed_openpnp_errors_name_the_element() {
    let board = |placement: &str| {
        format!(
            "<openpnp-board name=\"b\">\n<placements>\n{placement}\n</placements>\n</openpnp-board>"
        )
    };
    let cases = [
        (
            r#"<placement id="R1"><location units="Millimeters"/></placement>"#,
            "line 3: <placement id=\"R1\"> has no attribute `side`",
        ),
        (
            r#"<placement id="R1" side="top"><location units="Millimeters"/></placement>"#,
            "line 3: <placement id=\"R1\">: attribute `side` has invalid value `top`",
        ),
        (
            "<placement id=\"R1\" side=\"Top\">\n<location units=\"Millimeters\" x=\"1,5\"/></placement>",
            "line 4: <location of R1>: attribute `x` has invalid value `1,5`",
        ),
        (
            r#"<placement id="R1" side="Top"><location units="Parsecs"/></placement>"#,
            "line 3: <location of R1>: attribute `units` has invalid value `Parsecs`",
        ),
        (
            r#"<placement id="R1" side="Top"/>"#,
            "line 3: <placement id=\"R1\"> has no <location>",
        ),
        (
            r#"<placement side="Top"/>"#,
            "line 3: <placement> has no attribute `id`",
        ),
    ];
    for (placement, message) in cases {
        let err = read_openpnp_board(&board(placement)).expect_err(placement);
        assert_eq!(err.to_string(), message);
    }
    let err = read_openpnp_board("<openpnp-job/>").expect_err("a job");
    assert!(matches!(err, PnpError::NotABoard { found } if found == "openpnp-job"));
    let err =
        read_openpnp_board("<openpnp-board>\n<placements>\n</openpnp-board>").expect_err("bad");
    assert!(err.to_string().starts_with("line 3: XML error"), "{err}");
    let err = read_openpnp_board("<openpnp-board>\n<placements>").expect_err("truncated");
    assert!(
        matches!(err, PnpError::UnexpectedEof { .. } | PnpError::Xml { .. }),
        "{err}"
    );
    assert!(matches!(
        read_openpnp_board(""),
        Err(PnpError::NotABoard { .. })
    ));
}
