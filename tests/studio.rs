//! `conduit studio` on the circuit demo: the server refuses other hosts, other origins and
//! malformed requests with a 4xx; in a real browser a dragged part is saved moved by the drag,
//! a part typed out of the solid is flagged, and *Route* draws traces.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use serde_json::Value;

use crate::browser::{Browser, number};
use crate::support::{sample, temp_dir};

/// The running server, stopped when dropped.
struct Server {
    child: Child,
    port: u16,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn start(placement: &std::path::Path) -> Server {
    start_with("circuit_demo/led_coin.sch", Some(placement))
}

/// The studio of the demo block with `circuit` (a sample) and, when given, `placement`.
fn start_with(circuit: &str, placement: Option<&std::path::Path>) -> Server {
    let mut command = Command::new(env!("CARGO_BIN_EXE_conduit"));
    command
        .arg("studio")
        .arg(sample("circuit_demo/block.stl"))
        .arg("--circuit")
        .arg(sample(circuit));
    if let Some(p) = placement {
        command.arg("--placement").arg(p);
    }
    let mut child = command
        .args(["--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("conduit studio starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("the address is printed");
    let port = line
        .trim()
        .strip_prefix("conduit studio: http://127.0.0.1:")
        .and_then(|r| r.split('/').next())
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no address in {line:?}"));
    Server { child, port }
}

/// One HTTP/1.1 request with the given extra headers; the status and body.
fn request(port: u16, method: &str, path: &str, headers: &[&str], body: &str) -> (u16, String) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("the server answers");
    let mut text = format!(
        "{method} {path} HTTP/1.1\r\nConnection: close\r\nContent-Length: {}\r\n",
        body.len()
    );
    if !headers.iter().any(|h| h.starts_with("Host:")) {
        text.push_str(&format!("Host: 127.0.0.1:{port}\r\n"));
    }
    for h in headers {
        text.push_str(h);
        text.push_str("\r\n");
    }
    text.push_str("\r\n");
    text.push_str(body);
    s.write_all(text.as_bytes()).expect("the request is sent");
    let mut answer = String::new();
    s.read_to_string(&mut answer).expect("the answer is read");
    let status = answer
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    let body = answer
        .split("\r\n\r\n")
        .nth(1)
        .unwrap_or_default()
        .to_owned();
    (status, body)
}

const JSON: &str = "Content-Type: application/json";

#[test]
fn studio_refuses_other_hosts_origins_and_malformed_requests() {
    let dir = temp_dir();
    let placement = dir.path().join("placement.toml");
    std::fs::copy(sample("circuit_demo/placement.toml"), &placement).expect("copied");
    let server = start(&placement);
    let port = server.port;
    let (status, page) = request(port, "GET", "/", &[], "");
    assert_eq!(status, 200);
    assert!(page.contains("conduit/studio"), "the studio page");
    let (status, _) = request(port, "GET", "/", &["Host: evil.example"], "");
    assert_eq!(status, 403, "another host");
    let (status, body) = request(
        port,
        "POST",
        "/api/place",
        &[JSON, "Origin: http://evil.example"],
        r#"{"parts":[]}"#,
    );
    assert_eq!(
        (status, body.contains("other sites")),
        (403, true),
        "{body}"
    );
    for bad in [
        r#"{"parts":["#,
        r#"{"parts":[{"name":"NOPE","x":0,"y":0,"z":0,"rotation":0}]}"#,
        r#"{"parts":[{"name":"R1","x":1e999,"y":0,"z":0,"rotation":0}]}"#,
        r#"{"parts":[{"name":"R1"}]}"#,
        r#"{"parts":[], "extra": 1}"#,
        "\u{0}\u{1}garbage",
    ] {
        let (status, body) = request(port, "POST", "/api/place", &[JSON], bad);
        assert!((400..500).contains(&status), "{bad:?}: {status} {body}");
    }
    let (status, _) = request(
        port,
        "POST",
        "/api/save",
        &["Content-Type: text/plain"],
        "x",
    );
    assert!((400..500).contains(&status));
    assert_eq!(request(port, "GET", "/nope", &[], "").0, 404);
    // Still serving, and the file untouched by the refused requests.
    assert_eq!(request(port, "GET", "/api/progress", &[], "").0, 200);
    assert_eq!(
        std::fs::read_to_string(&placement).expect("readable"),
        std::fs::read_to_string(sample("circuit_demo/placement.toml")).expect("readable")
    );
}

/// R1's pose in a placement TOML.
fn r1(toml_text: &str) -> (f64, f64) {
    let doc: toml::Table = toml_text.parse().expect("the saved placement is TOML");
    let part = doc["part"]
        .as_array()
        .expect("parts")
        .iter()
        .find(|p| p["name"].as_str() == Some("R1"))
        .expect("R1 is saved");
    let f = |k: &str| {
        part[k]
            .as_float()
            .or_else(|| part[k].as_integer().map(|i| i as f64))
            .expect("a number")
    };
    (f("x"), f("y"))
}

#[test]
fn studio_drag_saves_the_move_flags_a_part_outside_and_routes() {
    let Some(browser) = Browser::start() else {
        return;
    };
    let dir = temp_dir();
    let placement = dir.path().join("placement.toml");
    std::fs::copy(sample("circuit_demo/placement.toml"), &placement).expect("copied");
    let (x0, y0) = r1(&std::fs::read_to_string(&placement).expect("readable"));
    let server = start(&placement);
    browser
        .open(
            &format!("http://127.0.0.1:{}/", server.port),
            Duration::from_secs(60),
        )
        .expect("the studio loads");
    assert_eq!(browser.console_errors(), Vec::<String>::new());

    // From the top: R1's footprint centre on screen and the screen scale on its plane.
    browser.eval("window.conduitView.setView('top'); return 0;");
    let probe = browser.eval(
        "const p = window.conduitView.data.circuit.parts.find((p) => p.name === 'R1'); \
         let x = 0, y = 0; for (const q of p.outline) { x += q[0]; y += q[1]; } \
         x /= p.outline.length; y /= p.outline.length; \
         return [window.conduitView.project([x, y, p.z]), window.conduitView.project([x + 1, y, p.z])];",
    );
    let (sx, sy) = (number(&probe[0][0]), number(&probe[0][1]));
    let px_per_mm = number(&probe[1][0]) - sx;
    assert!(
        px_per_mm > 3.0,
        "R1 is large enough on screen: {px_per_mm} px/mm"
    );
    browser.keep_screenshot("studio_before_drag");
    let drag_px = 60.0;
    browser.drag((sx, sy), (sx + drag_px, sy), 6);
    assert!(
        browser.wait_for(
            "return window.conduitStudio.checks > 0 && document.getElementById('studio-status').textContent === '';",
            Duration::from_secs(20)
        ),
        "the checks answer the drag"
    );
    browser.click("#save");
    assert!(
        browser.wait_for(
            "return window.conduitStudio.saves === 1;",
            Duration::from_secs(20)
        ),
        "saved: {}",
        browser.eval("return window.conduitStudio.status();")
    );
    let (x1, y1) = r1(&std::fs::read_to_string(&placement).expect("saved"));
    // The same placement as Electronic Slic3r's .3de, from the block's centre (40 × 30 mm; the
    // TOML rounds to the micrometre).
    browser.click("#export-3de");
    assert!(
        browser.wait_for(
            "return window.conduitStudio.exports === 1;",
            Duration::from_secs(20)
        ),
        "exported: {}",
        browser.eval("return window.conduitStudio.status();")
    );
    let three_de = conduit::circuit::Placement::from_3de(
        &std::fs::read_to_string(placement.with_extension("3de")).expect("the .3de is written"),
    )
    .expect("the .3de reads back");
    let r1_3de = three_de
        .parts
        .iter()
        .find(|p| p.name == "R1")
        .expect("R1 in the .3de");
    assert!(
        (r1_3de.x - (x1 - 20.0)).abs() < 1e-3 && (r1_3de.y - (y1 - 15.0)).abs() < 1e-3,
        "R1 in the .3de at ({}, {})",
        r1_3de.x,
        r1_3de.y
    );
    let want = drag_px / px_per_mm;
    assert!(
        (x1 - x0 - want).abs() < 0.25 && (y1 - y0).abs() < 0.25,
        "R1 moved by ({:.3}, {:.3}) mm, the drag was {want:.3} mm along x",
        x1 - x0,
        y1 - y0
    );
    browser.keep_screenshot("studio_after_drag");

    // Typed far outside the block: flagged at once, in the list and in the 3D labels.
    browser.retype(r#"input.pose-x[data-part="R1"]"#, "500");
    assert!(
        browser.wait_for(
            "return window.conduitStudio.flagged().includes('R1');",
            Duration::from_secs(20)
        ),
        "R1 outside the solid is flagged"
    );
    assert_eq!(
        browser.eval(
            "return document.querySelector('.part-row[data-part=\"R1\"]').classList.contains('flagged');"
        ),
        Value::Bool(true)
    );
    // Back inside, then routed.
    browser.retype(r#"input.pose-x[data-part="R1"]"#, &format!("{x0}"));
    assert!(
        browser.wait_for(
            "return !window.conduitStudio.flagged().includes('R1');",
            Duration::from_secs(20)
        ),
        "back inside, R1 is not flagged"
    );
    browser.click("#route");
    assert!(
        browser.wait_for(
            "return window.conduitStudio.routes === 1;",
            Duration::from_secs(300)
        ),
        "routed: {}",
        browser.eval("return window.conduitStudio.status();")
    );
    let state = browser.eval("return window.conduitView.state();");
    let traces: u64 = state["groups"]
        .as_array()
        .expect("groups")
        .iter()
        .filter(|g| g["role"] == "Conductive trace" && g["visible"] == true)
        .map(|g| g["drawn"].as_u64().unwrap_or(0))
        .sum();
    assert!(traces > 0, "traces are drawn: {state}");
    let status = browser.eval("return window.conduitStudio.status();");
    assert!(
        status
            .as_str()
            .is_some_and(|s| s.starts_with("routed: 4 of 4 wires connected")),
        "{status}"
    );
    let shot = browser.keep_screenshot("studio_routed");
    crate::view::write_picture("studio.png", || shot.encode_png().expect("encodes"));
    assert_eq!(browser.console_errors(), Vec::<String>::new());
}

/// The studio's data in its page.
fn page_data(page: &str) -> Value {
    let start = page
        .find(r#"<script type="application/json" id="conduit-data">"#)
        .expect("the data element")
        + r#"<script type="application/json" id="conduit-data">"#.len();
    let end = start + page[start..].find("</script>").expect("its end");
    serde_json::from_str(&page[start..end]).expect("the data is JSON")
}

#[test]
fn studio_starts_from_the_board_layout_or_packs_the_parts() {
    for circuit in ["circuit_demo/led_coin.brd", "circuit_demo/led_coin.sch"] {
        let server = start_with(circuit, None);
        let (status, page) = request(server.port, "GET", "/", &[], "");
        assert_eq!(status, 200, "{circuit}");
        let data = page_data(&page);
        let mut names: Vec<&str> = data["studio"]["parts"]
            .as_array()
            .expect("parts")
            .iter()
            .map(|p| p["name"].as_str().unwrap_or_default())
            .collect();
        names.sort_unstable();
        assert_eq!(names, ["BAT1", "LED1", "R1"], "{circuit}");
        assert_eq!(
            data["studio"]["flagged"],
            Value::Array(Vec::new()),
            "{circuit}: every part fits: {}",
            data["studio"]["problems"]
        );
        // Every wire is a rubberband before the first route.
        assert_eq!(
            data["circuit"]["unrouted"].as_array().map(Vec::len),
            data["circuit"]["wires"].as_u64().map(|n| n as usize),
            "{circuit}"
        );
    }
}
