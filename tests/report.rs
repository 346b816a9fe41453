//! `cryoslosh report` (issue 15): on shipped campaigns' runs every plot is written, labelled with its quantity and SI unit, referenced from index.html, and the page renders in headless Chromium with every image loaded and no console error.

mod common;
use common::campaign_path;
use common::report::{check_plots, cryoslosh, images, ok, run_and_report, scratch};
use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn report_of_a_run_labels_every_plot_and_references_only_existing_files() {
    let dir = scratch("mhtb");
    let report = run_and_report(&dir, "mhtb_selfpress", "64", &[]);
    let svgs = check_plots(&report);
    for expected in [
        "hist_peak_pressure_pa.svg",
        "exceed_peak_pressure_pa.svg",
        "hist_boiloff_kg.svg",
        "spearman_peak_pressure_pa.svg",
        "scatter_peak_pressure_pa.svg",
        "worst_peak_pressure_pa.svg",
        "worst2_peak_pressure_pa.svg",
        "worst3_peak_pressure_pa.svg",
        "worst_boiloff_kg.svg",
    ] {
        assert!(
            svgs.iter().any(|s| s == expected),
            "no {expected} in {svgs:?}"
        );
    }
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    for needle in [
        "mhtb_selfpress",
        "latin_hypercube",
        "<details>",
        "prob_exceed",
        "vented_kg: constant",
    ] {
        assert!(html.contains(needle), "index.html lacks {needle}");
    }
    // The MEOP threshold row appears with its interval in the probability table.
    assert!(html.contains("350000 Pa"), "no MEOP threshold in the table");
    // A published directory: the manifest lists every file.
    let manifest = std::fs::read_to_string(report.join("manifest.json")).unwrap();
    assert!(manifest.contains("index.html") && manifest.contains("hist_peak_pressure_pa.svg"));
    // A second report replaces the first whole.
    let run = dir.join("run");
    ok(&cryoslosh(&[
        "report",
        run.to_str().unwrap(),
        "--no-worst-cases",
    ]));
    assert!(!report.join("worst_peak_pressure_pa.svg").exists());
    assert!(report.join("hist_peak_pressure_pa.svg").exists());
}

#[test]
fn saltelli_run_reports_sobol_indices_and_a_shipped_mission_its_phases() {
    let dir = scratch("saltelli");
    let report = run_and_report(
        &dir,
        "mhtb_selfpress",
        "50",
        &["--set", "dispersions.design=saltelli"],
    );
    let svgs = check_plots(&report);
    assert!(
        svgs.iter().any(|s| s == "sobol_peak_pressure_pa.svg"),
        "{svgs:?}"
    );
    let svg = std::fs::read_to_string(report.join("sobol_peak_pressure_pa.svg")).unwrap();
    assert!(svg.contains("first order S_i") && svg.contains("total S_Ti"));

    // The LH2 upper stage: burns and coasts, a relief valve, an engine that draws.
    let dir = scratch("lh2");
    let report = run_and_report(&dir, "lh2_upper_stage", "16", &[]);
    let svgs = check_plots(&report);
    assert!(
        svgs.iter()
            .any(|s| s == "worst_min_cavitation_margin_m.svg"),
        "{svgs:?}"
    );
    let svg = std::fs::read_to_string(report.join("worst_min_cavitation_margin_m.svg")).unwrap();
    assert!(svg.contains("▸ burn1"), "phase boundaries are not named");
    assert!(
        svg.contains("relief crack") && svg.contains("MEOP"),
        "pressure limits missing"
    );
    // The regulator holds the peak pressure: a constant QoI gets a note, not a plot.
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(
        html.contains("peak_pressure_pa: constant"),
        "no note for a constant QoI"
    );
}

#[test]
fn per_phase_columns_show_up_without_being_listed() {
    if !common::python_with("pyarrow") {
        return;
    }
    let dir = scratch("phases");
    let run = dir.join("run");
    let path = campaign_path("mhtb_selfpress");
    ok(&cryoslosh(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--instances",
        "40",
        "--backend",
        "cpu",
    ]));
    // Add a `<qoi>.<phase>` column as the per-phase QoIs will, keeping the file metadata.
    let file = run.join("instances.parquet");
    let script = format!(
        "import pyarrow.parquet as pq, pyarrow.compute as pc\n\
         t = pq.read_table({f:?})\n\
         meta = {{k: v for k, v in pq.ParquetFile({f:?}).metadata.metadata.items() if k != b'ARROW:schema'}}\n\
         t = t.append_column('boiloff_kg.hold', pc.multiply(t['boiloff_kg'], 0.5))\n\
         t = t.replace_schema_metadata(meta)\n\
         pq.write_table(t, {f:?})\n",
        f = file.to_str().unwrap()
    );
    let py = Command::new("python3")
        .args(["-c", &script])
        .output()
        .unwrap();
    ok(&py);
    ok(&cryoslosh(&[
        "report",
        run.to_str().unwrap(),
        "--no-worst-cases",
    ]));
    let report = run.join("report");
    check_plots(&report);
    let svg = std::fs::read_to_string(report.join("hist_boiloff_kg-hold.svg")).unwrap();
    assert!(
        svg.contains("boiloff_kg.hold (kg)"),
        "per-phase axis label missing"
    );
}

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let dir = scratch("bad");
    let missing = dir.join("missing");
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let fake = dir.join("fake");
    std::fs::create_dir_all(&fake).unwrap();
    std::fs::write(fake.join("instances.parquet"), "not parquet").unwrap();
    std::fs::write(fake.join("statistics.parquet"), "not parquet").unwrap();
    for d in [&missing, &empty, &fake] {
        let o = cryoslosh(&["report", d.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{}: {err}", d.display());
        assert!(
            err.contains(d.to_str().unwrap()),
            "message does not name the path: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!d.join("report").exists());
    }
    // --out onto a directory of other files is refused; nothing there is touched.
    let run = dir.join("run");
    let path = campaign_path("mhtb_selfpress");
    ok(&cryoslosh(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--instances",
        "20",
        "--backend",
        "cpu",
        "--report",
    ]));
    // `run --report` wrote the report at the end of the run.
    check_plots(&run.join("report"));
    let o = cryoslosh(&[
        "report",
        run.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!run.join("index.html").exists());
    // A run.json that is there but not JSON is bad input, not a blank header.
    let other = dir.join("other");
    std::fs::create_dir_all(&other).unwrap();
    for f in ["instances.parquet", "statistics.parquet"] {
        std::fs::copy(run.join(f), other.join(f)).unwrap();
    }
    std::fs::write(other.join("run.json"), "{").unwrap();
    let o = cryoslosh(&["report", other.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("run.json"), "{err}");
    assert!(!other.join("report").exists());
}

/// The Chromium binary, or None (a failure when CI requires it).
fn chromium() -> Option<PathBuf> {
    let found = ["chromium", "chromium-browser"].iter().find_map(|name| {
        Command::new(name)
            .arg("--version")
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|_| PathBuf::from(name))
    });
    if found.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "chromium is required in CI (.ci/run installs Debian's chromium)"
        );
        eprintln!("skipped: chromium not installed (apt-get install chromium)");
    }
    found
}

/// Headless Chromium with the flags every call needs (no sandbox: CI runs as root).
fn headless(bin: &Path) -> Command {
    let mut c = Command::new(bin);
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--hide-scrollbars",
        "--enable-logging=stderr",
        "--v=0",
    ]);
    c
}

/// A script placed first in a copy of index.html: after load it writes each image's natural
/// width and every error event (a resource that failed, an exception, console.error) into the
/// DOM, which `--dump-dom` then prints.
const PROBE: &str = r#"<script>
window.probeErrors = [];
window.addEventListener('error', function (e) {
  var t = e.target;
  window.probeErrors.push(t && t.src ? 'failed to load ' + t.src : 'error ' + e.message);
}, true);
var originalError = console.error;
console.error = function () {
  window.probeErrors.push('console.error ' + Array.prototype.join.call(arguments, ' '));
  originalError.apply(console, arguments);
};
window.addEventListener('load', function () {
  var out = [];
  for (var i = 0; i < document.images.length; i++) {
    var img = document.images[i];
    out.push(img.getAttribute('src') + '=' + img.naturalWidth);
  }
  var p = document.createElement('pre');
  p.id = 'probe';
  p.textContent = 'IMAGES ' + out.join(' ') + '\nERRORS ' + window.probeErrors.length + ' ' + window.probeErrors.join(' | ') + '\nEND';
  document.body.appendChild(p);
});
</script>"#;

#[test]
fn index_html_renders_in_headless_chromium_with_every_image_loaded() {
    let Some(bin) = chromium() else {
        return;
    };
    let dir = scratch("chromium");
    let report = run_and_report(&dir, "lh2_upper_stage", "16", &[]);
    let index = report.join("index.html");

    // 1. Screenshot of the page as published: not blank.
    let shot = dir.join("page.png");
    let o = headless(&bin)
        .arg(format!("--screenshot={}", shot.display()))
        .arg("--window-size=1280,4000")
        .arg(format!("file://{}", index.display()))
        .output()
        .unwrap();
    ok(&o);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !stderr.contains(":CONSOLE"),
        "console output while rendering: {stderr}"
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buf).unwrap();
    let bytes = &buf[..frame.buffer_size()];
    let channels = frame.color_type.samples();
    let pixels = bytes.len() / channels;
    let dark = bytes
        .chunks(channels)
        .filter(|p| p.iter().take(3).any(|&c| c < 200))
        .count();
    assert!(
        (frame.width, frame.height) == (1280, 4000),
        "screenshot is {}×{}",
        frame.width,
        frame.height
    );
    // Text, axes and bars: a blank or failed page has (almost) no dark pixels.
    assert!(
        dark * 100 > pixels,
        "the screenshot is blank: {dark} dark pixels of {pixels}"
    );

    // 2. Every image loaded and no error, read back from the DOM.
    let html = std::fs::read_to_string(&index).unwrap();
    let probed = html.replacen("<head>", &format!("<head>\n{PROBE}"), 1);
    let probe = report.join("probe.html");
    std::fs::write(&probe, probed).unwrap();
    let o = headless(&bin)
        .arg("--virtual-time-budget=20000")
        .arg("--dump-dom")
        .arg(format!("file://{}", probe.display()))
        .output()
        .unwrap();
    ok(&o);
    let _ = std::fs::remove_file(&probe);
    let dom = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains(":CONSOLE"), "console output: {stderr}");
    let text = dom
        .split("<pre id=\"probe\">")
        .nth(1)
        .and_then(|s| s.split("END").next())
        .unwrap_or_else(|| panic!("the probe did not run: {dom}"));
    let line = |tag: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(tag))
            .unwrap_or_else(|| panic!("no {tag} in {text}"))
            .to_string()
    };
    let imgs = line("IMAGES ");
    let shown = images(&html);
    let widths: Vec<(&str, u32)> = imgs
        .split_whitespace()
        .map(|s| {
            let (src, w) = s.rsplit_once('=').unwrap();
            (src, w.parse().unwrap())
        })
        .collect();
    assert_eq!(widths.len(), shown.len(), "{imgs}");
    for (src, w) in &widths {
        assert!(*w > 0, "{src} did not load (naturalWidth 0)");
    }
    assert_eq!(line("ERRORS ").trim(), "0", "errors on the page: {text}");
}
