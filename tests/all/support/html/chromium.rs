//! Headless Chromium for the report tests: load a page, dump its DOM or take a screenshot,
//! and collect the page's console messages from the browser's log.

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The Debian package's launcher (`apt-get install -y chromium`).
pub const CHROMIUM: &str = "/usr/bin/chromium";

/// How long one page may take before the browser is killed and the test fails.
const TIMEOUT: Duration = Duration::from_secs(120);

/// `None` (after printing a notice) when `SETTLE_SKIP_BROWSER=1`; otherwise the browser,
/// and a failing test when it is not installed.
pub fn browser() -> Option<PathBuf> {
    if std::env::var("SETTLE_SKIP_BROWSER").is_ok_and(|v| v == "1") {
        eprintln!("SETTLE_SKIP_BROWSER=1: browser test skipped");
        return None;
    }
    let path = PathBuf::from(CHROMIUM);
    assert!(
        path.exists(),
        "{CHROMIUM} is missing: install it (`apt-get install -y chromium`, or \
         scripts/browser-test.sh) or set SETTLE_SKIP_BROWSER=1"
    );
    Some(path)
}

/// What one browser run left: its standard output and the page's console lines.
#[derive(Debug)]
pub struct Visit {
    /// `--dump-dom` output (the DOM after load), or empty.
    pub stdout: String,
    /// Every console message the page produced (errors, uncaught exceptions, blocked
    /// loads, and any `console.log`: the report's script logs nothing).
    pub console: Vec<String>,
    /// Wall time of the browser run.
    pub elapsed: Duration,
}

/// Load `page` (with the URL fragment `fragment`, e.g. `#selftest`) in a fresh headless
/// browser with the extra arguments `args` (e.g. `--dump-dom`), 1280x2000 CSS pixels.
pub fn visit(browser: &Path, page: &Path, fragment: &str, args: &[&str]) -> Visit {
    let profile = tempfile::tempdir().expect("temporary profile folder");
    let url = format!("file://{}{fragment}", page.display());
    let start = Instant::now();
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--v=0",
            "--window-size=1280,2000",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(args)
        .arg(&url)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("chromium starts");
    // Read both pipes on threads so that a full pipe never blocks the browser.
    let mut out = child.stdout.take().expect("stdout piped");
    let mut err = child.stderr.take().expect("stderr piped");
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        out.read_to_string(&mut s).map(|_| s)
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        err.read_to_string(&mut s).map(|_| s)
    });
    loop {
        if child.try_wait().expect("wait for chromium").is_some() {
            break;
        }
        if start.elapsed() > TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish {url} within {TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let stdout = out.join().expect("stdout reader").expect("stdout text");
    let stderr = err.join().expect("stderr reader").expect("stderr text");
    Visit {
        stdout,
        console: console_lines(&stderr),
        elapsed: start.elapsed(),
    }
}

/// The console messages in Chromium's log: lines like
/// `[pid:tid:time:INFO:CONSOLE:12] "Uncaught ReferenceError: ...", source: file:///... (12)`.
pub fn console_lines(log: &str) -> Vec<String> {
    log.lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(str::to_string)
        .collect()
}

/// `Ok` when the page wrote nothing to the console.
pub fn console_clean(v: &Visit) -> Result<(), String> {
    if v.console.is_empty() {
        Ok(())
    } else {
        Err(format!("console messages:\n{}", v.console.join("\n")))
    }
}

/// The JSON the page's `#selftest` hook writes into `<pre id="selftest-result">`, from a
/// `--dump-dom` output; `None` when it is absent (the script did not run to its end).
pub fn selftest_result(dom: &str) -> Option<serde_json::Value> {
    let open = "<pre id=\"selftest-result\">";
    let start = dom.find(open)? + open.len();
    let end = start + dom[start..].find("</pre>")?;
    // The DOM serialiser escapes `&`, `<`, `>` (and non-breaking spaces) in text.
    let text = dom[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&nbsp;", "\u{a0}")
        .replace("&amp;", "&");
    Some(serde_json::from_str(&text).expect("selftest result is JSON"))
}

/// Load `page` with `#selftest` and the hook's `parameters` (e.g. `&col=run`, see
/// `settle::output::html`), require a clean console and no script errors, and return the hook's
/// result and the visit's wall time.
pub fn selftest(browser: &Path, page: &Path, parameters: &str) -> (serde_json::Value, Duration) {
    let v = visit(
        browser,
        page,
        &format!("#selftest{parameters}"),
        &["--dump-dom"],
    );
    console_clean(&v).expect("no console messages");
    let res = selftest_result(&v.stdout).expect("the selftest ran to its end");
    assert_eq!(res["errors"], serde_json::json!([]), "script errors");
    (res, v.elapsed)
}

/// A box of the page in CSS pixels, as the selftest reports it.
#[derive(Debug, Clone, Copy)]
pub struct Rect {
    pub x: f64,
    pub y: f64,
    pub w: f64,
    pub h: f64,
}

impl Rect {
    /// From the selftest's `{x, y, w, h}`.
    pub fn from_json(v: &serde_json::Value) -> Option<Rect> {
        Some(Rect {
            x: v["x"].as_f64()?,
            y: v["y"].as_f64()?,
            w: v["w"].as_f64()?,
            h: v["h"].as_f64()?,
        })
    }
}

/// The standard deviation of the luminance (0-255) of the part of `rect` inside the image,
/// and that part's share of the rect's area. A blank region has deviation 0.
pub fn region_spread(img: &image::RgbaImage, rect: Rect) -> (f64, f64) {
    let x0 = rect.x.max(0.0) as u32;
    let y0 = rect.y.max(0.0) as u32;
    let x1 = ((rect.x + rect.w).max(0.0) as u32).min(img.width());
    let y1 = ((rect.y + rect.h).max(0.0) as u32).min(img.height());
    if x1 <= x0 || y1 <= y0 {
        return (0.0, 0.0);
    }
    let (mut n, mut sum, mut sum2) = (0.0, 0.0, 0.0);
    for y in y0..y1 {
        for x in x0..x1 {
            let p = img.get_pixel(x, y).0;
            let l = 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]);
            n += 1.0;
            sum += l;
            sum2 += l * l;
        }
    }
    let mean = sum / n;
    let share = n / (rect.w * rect.h).max(1.0);
    (((sum2 / n) - mean * mean).max(0.0).sqrt(), share)
}
