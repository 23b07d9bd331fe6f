//! A real browser for the page tests: Debian's `chromium`, headless, driven through
//! `chromedriver` (WebDriver) with fantoccini. Tests that need it call [`Browser::start`], which
//! prints a skip line and returns `None` when either program is missing.
//!
//! Chromium runs with software WebGL (SwiftShader), a fresh profile per session and no
//! background networking (the machine's network is closed; its connection attempts would only
//! slow it down). Screenshots are kept under `target/browser-screenshots/` for the test log.

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use fantoccini::wd::WebDriverCompatibleCommand;
use fantoccini::{Client, ClientBuilder};
use serde_json::{Value, json};

/// Window size of every session, CSS px.
pub const WINDOW: (u32, u32) = (1280, 800);

/// A headless Chromium session.
pub struct Browser {
    rt: tokio::runtime::Runtime,
    client: Option<Client>,
    driver: Child,
    _profile: tempfile::TempDir,
}

/// The first of `names` on the PATH (or an absolute path that exists).
fn find(names: &[&str]) -> Option<PathBuf> {
    for name in names {
        let p = Path::new(name);
        if p.is_absolute() && p.is_file() {
            return Some(p.to_path_buf());
        }
        if let Some(paths) = std::env::var_os("PATH") {
            for dir in std::env::split_paths(&paths) {
                let c = dir.join(name);
                if c.is_file() {
                    return Some(c);
                }
            }
        }
    }
    None
}

/// `POST /session/{id}/se/log` `{"type": "browser"}`: chromedriver's console log (entries since
/// the last call).
#[derive(Debug)]
struct BrowserLog;

impl WebDriverCompatibleCommand for BrowserLog {
    fn endpoint(
        &self,
        base_url: &url::Url,
        session_id: Option<&str>,
    ) -> Result<url::Url, url::ParseError> {
        base_url.join(&format!(
            "session/{}/se/log",
            session_id.unwrap_or_default()
        ))
    }

    fn method_and_body(&self, _url: &url::Url) -> (http::Method, Option<String>) {
        (
            http::Method::POST,
            Some(json!({"type": "browser"}).to_string()),
        )
    }
}

impl Browser {
    /// Starts chromedriver and a headless Chromium session, or prints why not and returns
    /// `None` (the browser is not installed).
    pub fn start() -> Option<Browser> {
        let chromium = std::env::var_os("CONDUIT_CHROMIUM")
            .map(PathBuf::from)
            .or_else(|| find(&["chromium", "chromium-browser", "google-chrome"]));
        let driver = find(&["chromedriver", "/usr/lib/chromium/chromedriver"]);
        let (Some(chromium), Some(driver)) = (chromium, driver) else {
            println!(
                "skipped: chromium and chromedriver are needed (apt-get install chromium chromium-driver)"
            );
            return None;
        };
        let port = TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map(|a| a.port())
            .expect("a free port on loopback");
        let child = Command::new(&driver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("chromedriver starts");
        let profile = tempfile::tempdir().expect("a temporary profile folder");
        let rt = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .expect("a tokio runtime");
        let mut caps = serde_json::Map::new();
        caps.insert("browserName".into(), json!("chrome"));
        caps.insert(
            "goog:chromeOptions".into(),
            json!({
                "binary": chromium,
                "args": [
                    "--headless=new", "--no-sandbox", "--disable-gpu",
                    "--enable-unsafe-swiftshader", "--use-angle=swiftshader",
                    "--disable-background-networking", "--disable-component-update",
                    "--disable-sync", "--disable-quic", "--no-first-run",
                    "--disable-dev-shm-usage", "--hide-scrollbars",
                    "--force-device-scale-factor=1",
                    format!("--window-size={},{}", WINDOW.0, WINDOW.1),
                    format!("--user-data-dir={}", profile.path().display()),
                ],
            }),
        );
        caps.insert("goog:loggingPrefs".into(), json!({"browser": "ALL"}));
        let url = format!("http://127.0.0.1:{port}");
        let client = rt.block_on(async {
            let deadline = Instant::now() + Duration::from_secs(20);
            loop {
                let connector = hyper_util::client::legacy::connect::HttpConnector::new();
                match ClientBuilder::new(connector)
                    .capabilities(caps.clone())
                    .connect(&url)
                    .await
                {
                    Ok(c) => return c,
                    Err(e) if Instant::now() < deadline => {
                        let _ = e;
                        tokio::time::sleep(Duration::from_millis(100)).await;
                    }
                    Err(e) => panic!("no WebDriver session on {url}: {e}"),
                }
            }
        });
        Some(Browser {
            rt,
            client: Some(client),
            driver: child,
            _profile: profile,
        })
    }

    fn client(&self) -> &Client {
        self.client.as_ref().expect("the session is open")
    }

    /// Loads `url` and waits until the page says it is ready (`body[data-ready]`) or `timeout`
    /// passes; returns the milliseconds waited.
    pub fn open(&self, url: &str, timeout: Duration) -> Result<u128, String> {
        let start = Instant::now();
        self.rt
            .block_on(self.client().goto(url))
            .map_err(|e| format!("{url}: {e}"))?;
        loop {
            let ready =
                self.eval("return document.body && document.body.dataset.ready === 'true';");
            if ready == Value::Bool(true) {
                return Ok(start.elapsed().as_millis());
            }
            if start.elapsed() > timeout {
                return Err(format!(
                    "{url}: not ready after {timeout:?}; errors: {:?}",
                    self.console_errors()
                ));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Loads a file from disk.
    pub fn open_file(&self, path: &Path) -> Result<u128, String> {
        let abs = std::fs::canonicalize(path).map_err(|e| format!("{}: {e}", path.display()))?;
        self.open(
            &format!("file://{}", abs.display()),
            Duration::from_secs(60),
        )
    }

    /// Runs `script` (a function body; `arguments` are not passed) and returns its value.
    pub fn eval(&self, script: &str) -> Value {
        self.rt
            .block_on(self.client().execute(script, Vec::new()))
            .unwrap_or_else(|e| panic!("script failed: {e}\n{script}"))
    }

    /// Errors of the page: console errors and uncaught exceptions from the browser's log, and
    /// the page's own list (`window.conduitErrors`, which also holds module load failures).
    pub fn console_errors(&self) -> Vec<String> {
        let mut errors = Vec::new();
        if let Ok(Value::Array(entries)) = self.rt.block_on(self.client().issue_cmd(BrowserLog)) {
            for e in entries {
                if e["level"] == "SEVERE" {
                    errors.push(e["message"].as_str().unwrap_or_default().to_owned());
                }
            }
        }
        if let Value::Array(own) =
            self.eval("return window.conduitErrors ? window.conduitErrors.slice() : [];")
        {
            errors.extend(own.into_iter().map(|v| v.to_string()));
        }
        errors
    }

    /// Takes a screenshot and keeps it as `target/browser-screenshots/NAME.png`.
    pub fn keep_screenshot(&self, name: &str) -> tiny_skia::Pixmap {
        let png = self
            .rt
            .block_on(self.client().screenshot())
            .expect("a screenshot");
        let dir = crate::support::root().join("target/browser-screenshots");
        let _ = std::fs::create_dir_all(&dir);
        let path = dir.join(format!("{name}.png"));
        std::fs::write(&path, &png).expect("the screenshot is kept");
        println!("screenshot: {}", path.display());
        tiny_skia::Pixmap::decode_png(&png).expect("the screenshot decodes")
    }

    /// The element matching the CSS selector `css`.
    pub fn find(&self, css: &str) -> fantoccini::elements::Element {
        self.rt
            .block_on(self.client().find(fantoccini::Locator::Css(css)))
            .unwrap_or_else(|e| panic!("no element {css}: {e}"))
    }

    /// Clicks the element matching `css`.
    pub fn click(&self, css: &str) {
        let el = self.find(css);
        self.rt
            .block_on(el.click())
            .unwrap_or_else(|e| panic!("cannot click {css}: {e}"));
    }

    /// Types `keys` into the element matching `css` (WebDriver key codes allowed).
    pub fn send_keys(&self, css: &str, keys: &str) {
        let el = self.find(css);
        self.rt
            .block_on(el.send_keys(keys))
            .unwrap_or_else(|e| panic!("cannot type into {css}: {e}"));
    }
}

impl Browser {
    /// Drags with the left mouse button from `from` to `to` (CSS px in the viewport) in `steps`
    /// moves, as a person would.
    pub fn drag(&self, from: (f64, f64), to: (f64, f64), steps: u32) {
        use fantoccini::actions::{InputSource, MOUSE_BUTTON_LEFT, MouseActions, PointerAction};
        let step = Some(Duration::from_millis(20));
        let mut mouse = MouseActions::new("mouse".into()).then(PointerAction::MoveTo {
            duration: step,
            x: from.0.round(),
            y: from.1.round(),
        });
        mouse = mouse.then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        });
        for k in 1..=steps {
            let f = f64::from(k) / f64::from(steps);
            mouse = mouse.then(PointerAction::MoveTo {
                duration: step,
                x: (from.0 + (to.0 - from.0) * f).round(),
                y: (from.1 + (to.1 - from.1) * f).round(),
            });
        }
        mouse = mouse.then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
        self.rt
            .block_on(self.client().perform_actions(mouse))
            .expect("the drag runs");
    }

    /// Replaces the value of the input matching `css` with `text` and leaves it (a change
    /// event).
    pub fn retype(&self, css: &str, text: &str) {
        let el = self.find(css);
        self.rt
            .block_on(async {
                el.clear().await?;
                el.send_keys(&format!("{text}\u{E004}")).await
            })
            .unwrap_or_else(|e| panic!("cannot type into {css}: {e}"));
    }

    /// Polls `condition` (a script returning a boolean) until it holds or `timeout` passes.
    pub fn wait_for(&self, condition: &str, timeout: Duration) -> bool {
        let start = Instant::now();
        while start.elapsed() < timeout {
            if self.eval(condition) == Value::Bool(true) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        false
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if let Some(client) = self.client.take() {
            let _ = self.rt.block_on(client.close());
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}

/// RGB of the pixel at (x, y) in device pixels.
pub fn rgb(img: &tiny_skia::Pixmap, x: f64, y: f64) -> [u8; 3] {
    let (x, y) = (x.round().max(0.0) as u32, y.round().max(0.0) as u32);
    let c = img
        .pixel(x.min(img.width() - 1), y.min(img.height() - 1))
        .expect("inside the image")
        .demultiply();
    [c.red(), c.green(), c.blue()]
}

/// A JSON number from the page.
pub fn number(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}
