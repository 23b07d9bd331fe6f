//! The view's HTML page: one self-contained file with three.js, the page's modules, its style
//! and the job data inlined, so it opens from disk and works offline.
//!
//! Place in the pipeline: the last step of `conduit view` (and the page `conduit studio`
//! serves). The modules are ES modules under `web/`; an import map gives each a bare name
//! (`three`, `three/addons/OrbitControls`, `conduit/main`…) mapped to a `data:` URL of its
//! text. three.js's module build imports its core as `./three.core.min.js`, which cannot be
//! resolved from a `data:` URL, so that one specifier is rewritten to `three/core` here.
//! The data is JSON in a `<script type="application/json">` with every `<` escaped as `\u003c`,
//! so no text of the data can close the element.

use serde::Serialize;

use super::encode::base64;
use super::job::JobView;
use super::overlay::{CircuitView, MeshView};

/// The modules of the page: (import name, source).
const MODULES: &[(&str, &str)] = &[
    ("three/core", include_str!("vendor/three/three.core.min.js")),
    ("three", include_str!("vendor/three/three.module.min.js")),
    (
        "three/addons/OrbitControls",
        include_str!("vendor/three/OrbitControls.js"),
    ),
    ("conduit/decode", include_str!("web/decode.js")),
    ("conduit/toolpaths", include_str!("web/toolpaths.js")),
    ("conduit/overlays", include_str!("web/overlays.js")),
    ("conduit/panel", include_str!("web/panel.js")),
    ("conduit/main", include_str!("web/main.js")),
];
/// The studio's own module, only in studio pages.
const STUDIO_MODULE: (&str, &str) = ("conduit/studio", include_str!("web/studio.js"));

/// Which page: the view of files, or the studio served by `conduit studio`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Entry {
    /// `conduit view`: a page that opens from disk.
    View,
    /// `conduit studio`: the view plus part editing against the local server.
    Studio,
}
const TEMPLATE: &str = include_str!("web/index.html");
const STYLE: &str = include_str!("web/style.css");

/// Everything one page shows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViewData {
    /// The G-code files, one job each (the page shows one at a time).
    pub jobs: Vec<JobView>,
    /// The model's objects, bed coordinates.
    pub models: Vec<MeshView>,
    /// The circuit, when given.
    pub circuit: Option<CircuitView>,
    /// The studio's editable placement (studio pages only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub studio: Option<super::studio::StudioView>,
}

/// The page of `data`, titled `title`, as HTML text.
///
/// # Errors
/// The data cannot be serialised (a non-finite number where JSON has none).
pub fn page(data: &ViewData, title: &str) -> Result<String, serde_json::Error> {
    page_for(data, title, Entry::View)
}

/// The page of `data` for `entry`.
///
/// # Errors
/// As [`page`].
pub fn page_for(data: &ViewData, title: &str, entry: Entry) -> Result<String, serde_json::Error> {
    let json = serde_json::to_string(data)?.replace('<', "\\u003c");
    let studio = (entry == Entry::Studio).then_some(&STUDIO_MODULE);
    let imports: serde_json::Map<String, serde_json::Value> = MODULES
        .iter()
        .chain(studio)
        .map(|(name, source)| {
            let source = if *name == "three" {
                source.replace("from\"./three.core.min.js\"", "from\"three/core\"")
            } else {
                (*source).to_owned()
            };
            (
                (*name).to_owned(),
                format!("data:text/javascript;base64,{}", base64(source.as_bytes())).into(),
            )
        })
        .collect();
    let import_map = serde_json::to_string_pretty(&serde_json::json!({ "imports": imports }))?;
    // Filled in one pass, so text of one part is never taken for a placeholder of another.
    let mut out = String::with_capacity(json.len() + import_map.len() + 64 * 1024);
    let mut rest = TEMPLATE;
    while let Some(start) = rest.find("{{") {
        let Some(len) = rest[start..].find("}}") else {
            break;
        };
        out.push_str(&rest[..start]);
        match &rest[start + 2..start + len] {
            "VERSION" => out.push_str(env!("CARGO_PKG_VERSION")),
            "TITLE" => out.push_str(&escape_html(title)),
            "STYLE" => out.push_str(STYLE),
            "IMPORTMAP" => out.push_str(&import_map),
            "DATA" => out.push_str(&json),
            "ENTRY" => out.push_str(match entry {
                Entry::View => "main",
                Entry::Studio => "studio",
            }),
            other => {
                out.push_str("{{");
                out.push_str(other);
                out.push_str("}}");
            }
        }
        rest = &rest[start + len + 2..];
    }
    out.push_str(rest);
    Ok(out)
}

/// `s` as HTML text.
fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_inlines_every_module_and_escapes_the_data() {
        let data = ViewData {
            jobs: Vec::new(),
            models: Vec::new(),
            circuit: None,
            studio: None,
        };
        let html = page(&data, "a <b> & c").expect("serialises");
        assert!(html.contains("<title>a &lt;b&gt; &amp; c</title>"));
        for (name, _) in MODULES {
            assert!(html.contains(&format!("\"{name}\": \"data:text/javascript;base64,")));
        }
        assert!(!html.contains("{{"), "every placeholder is filled");
        assert!(html.contains("import 'conduit/main';"));
        // The rewritten core import decodes from the map's `three` entry.
        let three = MODULES
            .iter()
            .find(|(n, _)| *n == "three")
            .map(|(_, s)| *s)
            .unwrap_or_default();
        assert!(three.contains("from\"./three.core.min.js\""));
        let json = serde_json::to_string(&serde_json::json!({"n": "</script>"}))
            .expect("json")
            .replace('<', "\\u003c");
        assert_eq!(
            serde_json::from_str::<serde_json::Value>(&json).expect("still JSON")["n"],
            "</script>"
        );
    }
}
