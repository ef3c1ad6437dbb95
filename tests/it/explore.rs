//! `rendersim explore` (src/explore): its lessons show what their text
//! says, every control is taken by the model at its slider's ends, the
//! page's numbers are `rendersim run --json`'s for the same `--set` list,
//! and the server answers bad requests with a message and a 4xx and stops
//! cleanly on Ctrl-C. The page itself is tested in headless Chromium
//! (`tests/browser/test_explore.py`).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

use rendersim::explore::controls::{CONTROLS, Control, Kind, assignment};
use rendersim::explore::page_run::{Explorer, PageResult};
use rendersim::explore::presets::PRESETS;

const DRAW: &str = "fidelity=\"draw\"";

fn explorer() -> Explorer {
    Explorer::new(None, vec![DRAW.into()], 50_000_000).unwrap()
}

fn lesson(id: &str, more: &[&str]) -> Vec<String> {
    let p = PRESETS.iter().find(|p| p.id == id).unwrap();
    std::iter::once(DRAW)
        .chain(p.sets.iter().copied())
        .chain(more.iter().copied())
        .map(String::from)
        .collect()
}

fn number(r: &PageResult, json: &str) -> f64 {
    r.numbers
        .iter()
        .find(|n| n.json == json)
        .unwrap_or_else(|| panic!("no number at {json}"))
        .value
        .unwrap_or(f64::NAN)
}

fn run(id: &str, more: &[&str]) -> PageResult {
    explorer()
        .run(&lesson(id, more), 4)
        .unwrap_or_else(|e| panic!("{id} {more:?}: {e}"))
}

const FRAME: &str = "metrics.frame_time_ms.mean";
const INTERVAL: &str = "metrics.display_interval_ms.mean";
const LATENCY: &str = "metrics.display_latency_ms.p50";

#[test]
fn each_lesson_shows_what_its_text_says() {
    // Vsync quantisation: 17.7 ms of GPU work is shown every 33.3 ms; under
    // 16.7 ms, every refresh.
    let slow = run("vsync-quantisation", &[]);
    assert!((number(&slow, INTERVAL) - 100.0 / 3.0).abs() < 1e-6);
    let fast = run("vsync-quantisation", &["gpu.fragment.per_fragment=\"9ns\""]);
    assert!((number(&fast, INTERVAL) - 50.0 / 3.0).abs() < 1e-6);
    // Table 1: geometry-bound, then fragment-bound as the fragment cost
    // rises; the GPU's frame lies between the slower stage and the sum.
    let t = run("table1", &[]);
    assert_eq!(t.verdict.bottleneck, "geometry");
    let gpu = number(&t, "metrics.gpu_time_ms.mean");
    let (geometry, fragment) = (t.closed_form[1].closed_form_ms, t.closed_form[2].closed_form_ms);
    assert!(
        gpu > geometry.max(fragment) && gpu < t.closed_form[3].closed_form_ms,
        "{gpu}"
    );
    assert_eq!(
        run("table1", &["gpu.fragment.per_fragment=\"6ns\""]).verdict.bottleneck,
        "fragment"
    );
    // Render-ahead: two frames more ahead, two GPU frames more of latency
    // at the same frame time.
    let three = run("render-ahead", &[]);
    let one = run("render-ahead", &["cpu.max_frames_ahead=1"]);
    let gpu = number(&three, "metrics.gpu_time_ms.mean");
    assert!((number(&three, FRAME) - number(&one, FRAME)).abs() < 1.5, "frame times");
    assert!(number(&three, LATENCY) > number(&one, LATENCY) + 0.9 * gpu, "latencies");
    // Triple buffering: 20 ms frames at 33.3 ms with two buffers, near 20
    // with three.
    let three = number(&run("triple-buffering", &[]), INTERVAL);
    let two = number(&run("triple-buffering", &["display.buffers=2"]), INTERVAL);
    assert!(
        (two - 100.0 / 3.0).abs() < 1e-6 && three > 50.0 / 3.0 && three < 21.0,
        "{two} {three}"
    );
    // A limiter before the frame: input waits too. Before the present:
    // same rate, the wait between input and screen.
    let start = run("limiter-place", &[]);
    let present = run("limiter-place", &["pacing.limit_from=\"present\""]);
    for r in [&start, &present] {
        assert!((number(r, INTERVAL) - 25.0).abs() < 0.01);
    }
    assert!(number(&present, LATENCY) > number(&start, LATENCY) + 10.0);
    // VRR below its range: repeated refreshes.
    let vrr = run("vrr-lfc", &[]);
    assert!(number(&vrr, "metrics.repeated_refresh_fraction") > 0.1);
    // Frame generation: twice the frames shown, more latency than without.
    let fg = run("frame-generation", &[]);
    let shown = number(&fg, "metrics.frame_generation.displayed_fps");
    let rendered = number(&fg, "metrics.frame_generation.rendered_fps");
    assert!((shown / rendered - 2.0).abs() < 0.05, "{shown} {rendered}");
    let off = run("frame-generation", &["frame_generation.enabled=false"]);
    assert!(number(&fg, LATENCY) > number(&off, LATENCY) + 2.0);
}

/// The assignments a control writes at its slider's ends (or each value),
/// in the form the page writes them (`controls::assignment`).
fn ends(control: &Control, key: &str) -> Vec<String> {
    let values: Vec<String> = match control.kind {
        Kind::Duration { min, max, .. } | Kind::Rate { min, max, .. } | Kind::Float { min, max, .. } => {
            vec![format!("{min:?}"), format!("{max:?}")]
        }
        Kind::Int { min, max } => vec![min.to_string(), max.to_string()],
        Kind::Bool => vec!["true".into(), "false".into()],
        Kind::Choice { options } => options.iter().map(|o| o.to_string()).collect(),
    };
    values
        .iter()
        .map(|v| assignment(control, key, v).unwrap_or_else(|e| panic!("{e}")))
        .collect()
}

#[test]
fn every_control_is_taken_by_the_model_at_its_sliders_ends() {
    let page = explorer();
    let model = page.page_model().unwrap();
    // The default model's scene shows its scene's knobs, not a fixed workload's.
    let keys: Vec<&str> = model.controls.iter().map(|c| c.control.key).collect();
    assert!(keys.contains(&"gpu.fragment.per_fragment") && !keys.contains(&"workload.gpu"));
    assert_eq!(model.controls.len(), CONTROLS.len() - 2);
    assert_eq!(model.presets.len(), PRESETS.len());
    // The fixed teaching model shows its own knobs, and only the lessons
    // whose keys it has.
    let fixed = concat!(env!("CARGO_MANIFEST_DIR"), "/models/fixed.toml");
    let fixed = Explorer::new(Some(std::path::Path::new(fixed)), vec![DRAW.into()], 1_000_000).unwrap();
    let m = fixed.page_model().unwrap();
    let keys: Vec<&str> = m.controls.iter().map(|c| c.control.key).collect();
    assert!(
        keys.contains(&"workload.gpu") && !keys.contains(&"gpu.fragment.per_fragment"),
        "{keys:?}"
    );
    assert!(m.presets.is_empty(), "the lessons are written for a scene");
    fixed.run(&[DRAW.into(), "workload.gpu=\"20ms\"".into()], 4).unwrap();
    for shown in &model.controls {
        for a in ends(&shown.control, &shown.set_key) {
            // Immediate presents need vsync off, VRR needs vsync on with a
            // panel faster than its floor: each end is tried where it can hold.
            let mut sets = vec![DRAW.to_string()];
            if a.contains("immediate") {
                sets.push("display.vsync=false".into());
            }
            if a.starts_with("display.vrr") {
                sets.push("display.refresh=\"360Hz\"".into());
            }
            if a.starts_with("display.vrr.max_refresh") {
                sets.push("display.vrr.min_refresh=\"20Hz\"".into());
            }
            if a.starts_with("display.refresh") && a.contains("\"20Hz\"") {
                sets.push("pacing.limit=\"20Hz\"".into());
            }
            sets.push(a.clone());
            if let Err(e) = page.model_toml(&sets) {
                panic!("{a}: {e}");
            }
        }
    }
}

#[test]
fn a_bad_value_gets_the_set_message_and_a_run_past_the_budget_is_refused() {
    let page = explorer();
    let e = page
        .run(&[DRAW.into(), "gpu.fragment.per_fragment=\"abc\"".into()], 4)
        .unwrap_err();
    assert_eq!(e.status(), 422);
    assert!(
        e.to_string().contains("--set gpu.fragment.per_fragment=\"abc\"") && e.to_string().contains("unknown unit"),
        "{e}"
    );
    let e = page.run(&[DRAW.into(), "system=\"present\"".into()], 4).unwrap_err();
    assert_eq!(e.status(), 400);
    let small = Explorer::new(None, vec![DRAW.into()], 1000).unwrap();
    let e = small.run(&[DRAW.into()], 4).unwrap_err();
    assert_eq!(e.status(), 422);
    assert!(e.to_string().contains("budget of 1000 events"), "{e}");
    // A model of another system is refused when the page starts.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("present.toml");
    std::fs::write(&p, "system = \"present\"\n").unwrap();
    let e = Explorer::new(Some(&p), vec![], 1000).unwrap_err().to_string();
    assert!(e.contains("explore shows the frame pipeline"), "{e}");
}

/// The value at dotted `path` of `v` (`metrics.frame_time_ms.mean`).
fn at<'a>(v: &'a serde_json::Value, path: &str) -> &'a serde_json::Value {
    path.split('.').fold(v, |v, k| &v[k])
}

#[test]
fn the_pages_numbers_are_rendersim_runs() {
    let page = explorer();
    let mut lists: Vec<Vec<String>> = vec![vec![DRAW.into()]];
    lists.extend(PRESETS.iter().map(|p| lesson(p.id, &[])));
    for sets in lists {
        let shown = page.run(&sets, 4).unwrap();
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_rendersim"));
        cmd.args(["run", "--json"]);
        for s in &sets {
            cmd.args(["--set", s]);
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        // serde_json reads a float back to within one unit in the last
        // place (without its `float_roundtrip` feature): equal to 1e-12.
        let same = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) => (a - b).abs() <= 1e-12 * a.abs().max(b.abs()),
            (a, b) => a == b,
        };
        for n in &shown.numbers {
            let cli = at(&json, n.json).as_f64();
            assert!(
                same(n.value, cli),
                "{sets:?}: {} ({}): {:?} {cli:?}",
                n.label,
                n.json,
                n.value
            );
        }
        for c in &shown.closed_form {
            assert!(
                same(Some(c.closed_form_ms), at(&json, c.closed_form_json).as_f64()),
                "{}",
                c.label
            );
            let simulated = match c.simulated_from.split_once(" / ") {
                None => at(&json, c.simulated_from).as_f64(),
                Some((busy, by)) => at(&json, busy).as_f64().map(|b| b / at(&json, by).as_f64().unwrap()),
            };
            assert!(
                same(c.simulated_ms, simulated),
                "{}: {:?} {simulated:?}",
                c.label,
                c.simulated_ms
            );
        }
        for (unit, share) in &shown.shares {
            let cli = json["metrics"]["bottleneck"][unit].as_f64();
            assert!(same(Some(*share), cli), "{unit}: {share} {cli:?}");
        }
        assert_eq!(
            shown.command,
            format!(
                "rendersim run {}",
                sets.iter()
                    .map(|s| format!("--set {}", rendersim::explore::page_run::shell_quote(s)))
                    .collect::<Vec<_>>()
                    .join(" ")
            )
        );
    }
}

/// A served page: the process, and its address.
struct Served {
    child: Child,
    addr: String,
}

impl Served {
    fn start(args: &[&str]) -> Served {
        let mut child = Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(["explore", "--port", "0"])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.as_mut().unwrap())
            .read_line(&mut line)
            .unwrap();
        let addr = line
            .split("http://")
            .nth(1)
            .and_then(|r| r.split('/').next())
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_string();
        Served { child, addr }
    }

    /// `GET path` (or another `method`): the status and the body.
    fn ask(&self, method: &str, path: &str) -> (u16, String) {
        self.send(method, path, None, &[])
    }

    /// A request with `body` (its length as `Content-Length`, or `length`
    /// where given, for a body announced but not sent).
    fn send(&self, method: &str, path: &str, length: Option<u64>, body: &[u8]) -> (u16, String) {
        let mut s = TcpStream::connect(&self.addr).unwrap();
        let length = length.unwrap_or(body.len() as u64);
        write!(
            s,
            "{method} {path} HTTP/1.0\r\nHost: {}\r\nContent-Length: {length}\r\n\r\n",
            self.addr
        )
        .unwrap();
        s.write_all(body).unwrap();
        let mut text = String::new();
        s.read_to_string(&mut text).unwrap();
        let status = text.split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
        let body = text.split_once("\r\n\r\n").map_or("", |(_, b)| b).to_string();
        (status, body)
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
    }
}

#[test]
fn the_server_answers_bad_requests_with_a_message_and_stops_on_ctrl_c() {
    let served = Served::start(&["--budget-events", "20000000"]);
    let (status, html) = served.ask("GET", "/");
    assert_eq!(status, 200);
    assert!(html.contains("rendersim explore") && html.contains("/app.js"));
    let (status, model) = served.ask("GET", "/api/model");
    assert_eq!(status, 200, "{model}");
    assert!(model.contains("\"start_sets\":[\"fidelity=\\\"draw\\\"\"]"), "{model}");
    let (status, body) = served.ask("GET", "/api/run?set=display.buffers%3D%22two%22");
    assert_eq!(status, 422);
    assert!(body.contains("--set display.buffers=\\\"two\\\""), "{body}");
    assert_eq!(served.ask("GET", "/api/run?frames=3").0, 400);
    assert_eq!(served.ask("GET", "/api/run?timeline=0").0, 400);
    assert_eq!(served.ask("POST", "/api/run").0, 405);
    assert_eq!(served.ask("GET", "/etc/passwd").0, 404);
    assert_eq!(served.ask("GET", "/../Cargo.toml").0, 404);
    let long = format!("/api/run?set={}", "x".repeat(20_000));
    assert_eq!(served.ask("GET", &long).0, 414);
    // Triangle fidelity over the whole default model is past this budget.
    let (status, body) = served.ask("GET", "/api/run?set=fidelity%3D%22triangle%22&set=run.frames%3D2000");
    assert_eq!(status, 422);
    assert!(body.contains("budget of 20000000 events"), "{body}");
    let (status, toml) = served.ask("GET", "/api/model.toml?set=display.buffers%3D3");
    assert_eq!(status, 200);
    assert!(toml.contains("buffers = 3"), "{toml}");
    // A capture dropped on the page: replayed from the upload, the
    // display's and pacing's controls as its what-if.
    let capture = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/presentmon/test_case_0.csv"
    ))
    .unwrap();
    let (status, body) = served.send(
        "POST",
        "/api/replay?file=test_case_0.csv&set=pacing.limit%3D%2230Hz%22",
        None,
        &capture,
    );
    assert_eq!(status, 200, "{body}");
    let r: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert!(r["agreement"].as_f64().unwrap() > 0.95, "{}", r["agreement"]);
    assert_eq!(
        r["command"],
        "rendersim replay test_case_0.csv --set 'pacing.limit=\"30Hz\"'"
    );
    assert!(
        r["whatif"][1]["fps"].as_f64().unwrap() < 30.5,
        "{}",
        r["whatif"][1]["fps"]
    );
    // A scene's key is no replay's what-if; a file that is no capture, an
    // empty one and one over the limit are refused with a message.
    let (status, body) = served.send("POST", "/api/replay?set=cpu.per_object%3D%221us%22", None, &capture);
    assert_eq!(status, 400, "{body}");
    let (status, body) = served.send("POST", "/api/replay?file=notes.txt", None, b"hello,world\n1,2\n");
    assert_eq!(status, 422, "{body}");
    assert!(body.contains("notes.txt"), "{body}");
    assert_eq!(served.send("POST", "/api/replay", None, b"").0, 400);
    let (status, body) = served.send("POST", "/api/replay", Some(1 << 40), b"");
    assert_eq!(status, 413, "{body}");
    assert!(body.contains("64 MiB"), "{body}");
    assert_eq!(served.ask("GET", "/api/replay").0, 405);
    // Still serving after all that; Ctrl-C (SIGINT) stops it with status 0.
    assert_eq!(
        served
            .ask("GET", "/api/run?set=fidelity%3D%22draw%22&set=run.frames%3D30")
            .0,
        200
    );
    let mut served = served;
    let pid = served.child.id().to_string();
    assert!(Command::new("kill").args(["-INT", &pid]).status().unwrap().success());
    let status = served.child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    let mut rest = String::new();
    served.child.stdout.take().unwrap().read_to_string(&mut rest).unwrap();
    assert!(rest.contains("stopped"), "{rest:?}");
}
