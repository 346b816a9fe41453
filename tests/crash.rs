//! A `run` or `merge` killed after its first rename used to leave new rows beside an older run's
//! statistics, and temporaries that were never cleaned. A results directory is now published whole
//! or not at all: killed at any failpoint (test hook `CRYOSLOSH_FAILPOINT`), the directory holds
//! the previous complete result or the new one; the next command on that path removes what the
//! killed one left; a second writer on the same directory is refused; merge checks its shards.

mod common;
use common::campaign_path;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    common::scratch_in("crash", name)
}

fn cryoslosh(args: &[&str], failpoint: Option<&str>) -> Output {
    common::cryoslosh_at(args, failpoint)
}

/// Every file under `dir` (relative path → bytes); `run.json` reduced to its seed (its wall
/// time differs between runs of the same result) and `manifest.json` left out.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                if p.file_name().unwrap() == "manifest.json" {
                    // Holds run.json's checksum; checked by merge, compared through the files.
                    continue;
                }
                let mut bytes = std::fs::read(&p).unwrap();
                if p.file_name().unwrap() == "run.json" {
                    let v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                    bytes = v["seed"].to_string().into_bytes();
                }
                out.insert(p.strip_prefix(dir).unwrap().to_path_buf(), bytes);
            }
        }
    }
    out
}

/// Names beside `dir` that a writer of `dir` leaves (staging, old copies), lock file excluded.
fn leftovers(dir: &Path) -> Vec<String> {
    let name = dir.file_name().unwrap().to_string_lossy().into_owned();
    std::fs::read_dir(dir.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| {
            n.starts_with(&format!(".{name}.tmp-"))
                || n.starts_with(&format!(".{name}.old-"))
                || *n == format!(".{name}.partial")
        })
        .collect()
}

fn run_args<'a>(camp: &'a str, out: &'a str, seed: &'a str) -> Vec<&'a str> {
    vec![
        "run",
        camp,
        "--out",
        out,
        "--instances",
        "12",
        "--seed",
        seed,
        "--backend",
        "cpu",
        "--set",
        "phases.0.duration_s=600",
        "--histories",
        "instance:3",
        "--force",
    ]
}

#[test]
fn a_killed_run_leaves_the_previous_result_or_the_new_one() {
    let camp = campaign_path("mhtb_selfpress");
    let camp = camp.to_str().unwrap();
    let root = scratch("run");
    let out = root.join("results");
    let outs = out.to_str().unwrap();
    // The new result, made once in a directory of its own, to compare against.
    let fresh = root.join("fresh");
    let o = cryoslosh(&run_args(camp, fresh.to_str().unwrap(), "2"), None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let new = snapshot(&fresh);
    let o = cryoslosh(&run_args(camp, outs, "1"), None);
    assert!(o.status.success());
    let old = snapshot(&out);
    assert_ne!(old, new);
    for (point, published) in [
        ("after-instances", false),
        ("after-statistics", false),
        ("before-publish", false),
        ("after-exchange", true),
    ] {
        let o = cryoslosh(&run_args(camp, outs, "2"), Some(point));
        assert!(
            !o.status.success(),
            "{point}: the failpoint must stop the process"
        );
        let now = snapshot(&out);
        if published {
            assert!(now == new, "{point}: the new result must be whole");
        } else {
            assert!(now == old, "{point}: the previous result must be untouched");
        }
        // The next command on that path cleans up and publishes (back to seed 1).
        let o = cryoslosh(&run_args(camp, outs, "1"), None);
        assert!(
            o.status.success(),
            "{point}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(leftovers(&out).is_empty(), "{point}: {:?}", leftovers(&out));
        assert!(
            snapshot(&out) == old,
            "{point}: rerun must reproduce the result"
        );
    }
    std::fs::remove_dir_all(root).ok();
}

#[test]
fn a_second_writer_of_one_directory_is_refused() {
    let camp = campaign_path("mhtb_selfpress");
    let root = scratch("lock");
    let out = root.join("results");
    let lock = std::fs::File::options()
        .create(true)
        .truncate(false)
        .write(true)
        .open(root.join(".results.lock"))
        .unwrap();
    lock.lock().unwrap(); // as another cryoslosh process holding the directory would
    let o = cryoslosh(
        &run_args(camp.to_str().unwrap(), out.to_str().unwrap(), "1"),
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("another cryoslosh process"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!out.exists());
    drop(lock);
    std::fs::remove_dir_all(root).ok();
}

/// Regression: an empty `.DIR.lock` stayed beside the results directory after every command.
/// It goes when the command ends (published, refused or failed); a killed one leaves it, and a
/// lock still held on a removed lock file (its holder's last act) does not block the next writer.
#[cfg(unix)]
#[test]
fn the_lock_file_goes_when_the_command_ends() {
    let camp = campaign_path("mhtb_selfpress");
    let camp = camp.to_str().unwrap();
    let root = scratch("lockfile");
    let out = root.join("results");
    let outs = out.to_str().unwrap();
    let lock = root.join(".results.lock");
    let mut args = run_args(camp, outs, "1");
    args.truncate(args.len() - 3); // no histories, no --force
    let o = cryoslosh(&args, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!lock.exists(), "after a published run");
    let o = cryoslosh(&args, None); // not empty without --force
    assert_eq!(o.status.code(), Some(2));
    assert!(!lock.exists(), "after a refused run");
    let forced = run_args(camp, outs, "2");
    let o = cryoslosh(&forced, Some("enospc:after-instances"));
    assert_eq!(o.status.code(), Some(1));
    assert!(!lock.exists(), "after a failed run");
    let o = cryoslosh(&forced, Some("after-instances"));
    assert!(!o.status.success());
    assert!(lock.exists(), "a killed run cannot remove it");
    let o = cryoslosh(&["report", outs, "--no-worst-cases"], None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.join(".report.lock").exists(), "after a report");
    // Another process that locked the file and removed it, still holding the lock.
    let held = std::fs::File::options().write(true).open(&lock).unwrap();
    held.lock().unwrap();
    std::fs::remove_file(&lock).unwrap();
    let o = cryoslosh(&forced, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        !lock.exists(),
        "after the run that cleaned up the killed one"
    );
    drop(held);
    std::fs::remove_dir_all(root).ok();
}

#[test]
fn merge_refuses_tampered_shards_and_its_own_input_and_a_killed_merge_publishes_nothing() {
    let camp = campaign_path("mhtb_selfpress");
    let camp = camp.to_str().unwrap();
    let root = scratch("merge");
    let shard = |i: u32| {
        let d = root.join(format!("s{i}"));
        let mut args = run_args(camp, d.to_str().unwrap(), "1");
        args.truncate(args.len() - 3); // no histories, no --force
        let spec = format!("{i}/2");
        let o = cryoslosh(&[&args[..], &["--shard", &spec]].concat(), None);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        d
    };
    let (s0, s1) = (shard(0), shard(1));
    let (s0s, s1s) = (s0.to_str().unwrap(), s1.to_str().unwrap());
    let merged = root.join("merged");
    let ms = merged.to_str().unwrap();
    // Killed (or out of disk) at any stage before publishing: nothing appears.
    for fp in [
        "merge-after-instances",
        "before-publish",
        "enospc:merge-after-instances",
        "enospc:before-publish",
    ] {
        let o = cryoslosh(&["merge", s0s, s1s, "--out", ms], Some(fp));
        assert!(!o.status.success(), "{fp}");
        assert!(!merged.exists(), "{fp}");
    }
    let o = cryoslosh(&["merge", s0s, s1s, "--out", ms], None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(leftovers(&merged).is_empty());
    // The output may not be an input.
    let o = cryoslosh(&["merge", s0s, s1s, "--out", s0s, "--force"], None);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("overlaps"));
    // A shard whose rows are relabelled (ids shifted by one: a gap and a foreign id) is named
    // and refused, and nothing is written.
    if common::python_with("pyarrow") {
        // Each class of tampering, the manifest rewritten to match (so that the content checks,
        // not the checksum, must catch it): refused with exit 2 naming the shard, nothing written.
        for (class, edit, needle) in [
            (
                "relabelled rows",
                "t = t.set_column(0, 'instance', pa.array([i + 1 for i in t.column('instance').to_pylist()], pa.uint64()))",
                "holds instance 1",
            ),
            (
                "duplicated row and a gap",
                "t = pa.concat_tables([t.slice(0, 1), t.slice(0, t.num_rows - 1)])",
                "row 1 holds instance 0",
            ),
            (
                "columns swapped",
                "n = t.column_names; i, j = n.index('peak_pressure_pa'), n.index('boiloff_kg'); n[i], n[j] = n[j], n[i]; t = t.rename_columns(n)",
                "column",
            ),
            (
                "int64 steps",
                "t = t.set_column(t.column_names.index('steps'), 'steps', t.column('steps').cast(pa.int64()))",
                "steps (Int64)",
            ),
            (
                "missing column",
                "t = t.drop_columns(['vented_kg'])",
                "column",
            ),
        ] {
            let bad = root.join("bad");
            let _ = std::fs::remove_dir_all(&bad);
            std::fs::create_dir_all(&bad).unwrap();
            for f in ["run.json", "statistics.parquet", "manifest.json"] {
                std::fs::copy(s0.join(f), bad.join(f)).unwrap();
            }
            let script = format!(
                "import pyarrow as pa, pyarrow.parquet as pq, hashlib, json\n\
                 t = pq.read_table('{0}')\n\
                 {edit}\n\
                 kv = {{k: v for k, v in pq.read_metadata('{0}').metadata.items() if k != b'ARROW:schema'}}\n\
                 pq.write_table(t.replace_schema_metadata(kv), '{1}')\n\
                 m = json.load(open('{2}'))\n\
                 data = open('{1}', 'rb').read()\n\
                 m['files']['instances.parquet'] = {{'bytes': len(data), 'sha256': hashlib.sha256(data).hexdigest()}}\n\
                 json.dump(m, open('{2}', 'w'))\n",
                s0.join("instances.parquet").display(),
                bad.join("instances.parquet").display(),
                bad.join("manifest.json").display()
            );
            let py = Command::new("python3").args(["-c", &script]).output().unwrap();
            assert!(py.status.success(), "{class}: {}", String::from_utf8_lossy(&py.stderr));
            let m2 = root.join("m2");
            let o = cryoslosh(
                &["merge", bad.to_str().unwrap(), s1s, "--out", m2.to_str().unwrap()],
                None,
            );
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{class}: {err}");
            assert!(err.contains("shard 0/2") && err.contains(needle), "{class}: {err}");
            assert!(!err.contains("panicked"), "{class}: {err}");
            assert!(!m2.exists(), "{class}");
        }
    }
    // A file changed after the run wrote it (one byte of shard 1's statistics) is caught by the
    // manifest's SHA-256 and named.
    let stats = s1.join("statistics.parquet");
    let mut bytes = std::fs::read(&stats).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 1;
    std::fs::write(&stats, bytes).unwrap();
    let m3 = root.join("m3");
    let o = cryoslosh(&["merge", s0s, s1s, "--out", m3.to_str().unwrap()], None);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("statistics.parquet differs"), "{err}");
    assert!(!m3.exists());
    std::fs::remove_dir_all(root).ok();
}

/// `run --resume` after a kill between committed blocks gives the uninterrupted bytes, for a plain
/// run and for a precision-driven one; it refuses another run's leftovers and an empty place.
#[test]
fn resume_after_a_kill_equals_the_uninterrupted_run() {
    let camp = campaign_path("mhtb_selfpress");
    let camp = camp.to_str().unwrap();
    let root = scratch("resume");
    let args = |out: &Path, seed: &str, extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = [
            "run",
            camp,
            "--out",
            out.to_str().unwrap(),
            "--instances",
            "300",
            "--seed",
            seed,
            "--backend",
            "cpu",
            "--chunk-size",
            "40",
            "--set",
            "phases.0.duration_s=600",
            "--set",
            "dispersions.design=monte_carlo",
        ]
        .iter()
        .map(|x| x.to_string())
        .collect();
        v.extend(extra.iter().map(|x| x.to_string()));
        v
    };
    let call = |a: &[String], fp: Option<&str>| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        cryoslosh(&refs, fp)
    };
    for (name, extra) in [
        ("plain", &[][..]),
        ("until", &["--until", "boiloff_kg@p50:0.0002"][..]),
    ] {
        let whole = root.join(format!("{name}-whole"));
        let o = call(&args(&whole, "4", extra), None);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let out = root.join(format!("{name}-killed"));
        // Killed after each committed block in turn, resumed, killed again at the next: the
        // run advances one block per kill and still ends with the uninterrupted bytes.
        // (The failpoint counts the blocks a process commits; a resumed run may finish first.)
        for k in 0..3 {
            let fp = format!("after-part-{k}");
            let resume = if k == 0 { &[][..] } else { &["--resume"][..] };
            let o = call(&args(&out, "4", &[extra, resume].concat()), Some(&fp));
            if k > 0 && o.status.success() {
                break;
            }
            assert!(
                !o.status.success(),
                "{name}: the failpoint {fp} must stop the run"
            );
            assert!(
                !out.exists(),
                "{name}: nothing is published by a killed run"
            );
        }
        let resume = [extra, &["--resume"]].concat();
        if !out.exists() {
            // Another run's leftovers are not resumed.
            let o = call(&args(&out, "5", &resume), None);
            assert_eq!(
                o.status.code(),
                Some(2),
                "{}",
                String::from_utf8_lossy(&o.stderr)
            );
            let o = call(&args(&out, "4", &resume), None);
            assert!(
                o.status.success(),
                "{name}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        for f in ["instances.parquet", "statistics.parquet"] {
            assert!(
                std::fs::read(whole.join(f)).unwrap() == std::fs::read(out.join(f)).unwrap(),
                "{name}: {f} of the resumed run differs from the uninterrupted one"
            );
        }
        assert!(leftovers(&out).is_empty(), "{:?}", leftovers(&out));
    }
    let o = call(&args(&root.join("none"), "4", &["--resume"]), None);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no interrupted run"));
    std::fs::remove_dir_all(root).ok();
}

/// A full disk at any write of a run (injected ENOSPC) fails it with exit 1 and the device's
/// message, leaves the previous result whole, and the next command cleans up.
#[test]
fn a_full_disk_at_any_point_leaves_the_previous_result() {
    let camp = campaign_path("mhtb_selfpress");
    let camp = camp.to_str().unwrap();
    let root = scratch("enospc");
    let out = root.join("results");
    let outs = out.to_str().unwrap();
    let o = cryoslosh(&run_args(camp, outs, "1"), None);
    assert!(o.status.success());
    let old = snapshot(&out);
    for point in [
        "after-part-0",
        "after-instances",
        "after-statistics",
        "before-publish",
    ] {
        let fp = format!("enospc:{point}");
        let o = cryoslosh(&run_args(camp, outs, "2"), Some(&fp));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{point}: {err}");
        assert!(err.contains("No space left on device"), "{point}: {err}");
        assert!(!err.contains("panicked"), "{point}: {err}");
        assert!(
            snapshot(&out) == old,
            "{point}: the previous result must be untouched"
        );
    }
    let o = cryoslosh(&run_args(camp, outs, "1"), None);
    assert!(o.status.success());
    assert!(leftovers(&out).is_empty(), "{:?}", leftovers(&out));
    assert!(snapshot(&out) == old);
    std::fs::remove_dir_all(root).ok();
}

/// A second attack on crash consistency: a resumed run trusted a copied part (published 1500
/// distinct ids of 2000 with exit 0); a kill after the last block threw the work away; a history
/// could be written into a published result; an emptied manifest or an edited run.json passed
/// merge; the odd shard was not named; a symlink `--out` got the wrong reason.
#[test]
fn second_attack_regressions() {
    let camp = campaign_path("mhtb_selfpress");
    let camp = camp.to_str().unwrap();
    let root = scratch("attack2");
    let args = |out: &Path, extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = [
            "run",
            camp,
            "--out",
            out.to_str().unwrap(),
            "--instances",
            "120",
            "--seed",
            "2",
            "--backend",
            "cpu",
            "--chunk-size",
            "40",
            "--set",
            "phases.0.duration_s=600",
        ]
        .iter()
        .map(|x| x.to_string())
        .collect();
        v.extend(extra.iter().map(|x| x.to_string()));
        v
    };
    let call = |a: &[String], fp: Option<&str>| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        cryoslosh(&refs, fp)
    };
    let whole = root.join("whole");
    assert!(call(&args(&whole, &[]), None).status.success());

    // A part copied over another is refused on resume.
    let r = root.join("r");
    assert!(!call(&args(&r, &[]), Some("after-part-1")).status.success());
    let parts = root.join(".r.partial").join("parts");
    std::fs::copy(
        parts.join("part-000000000000.parquet"),
        parts.join("part-000000000040.parquet"),
    )
    .unwrap();
    let o = call(&args(&r, &["--resume"]), None);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("changed after it was committed"));
    assert!(!r.exists());

    // Killed after every block is integrated: the resume integrates nothing and finishes.
    for point in ["after-instances", "after-statistics", "before-publish"] {
        let k = root.join(format!("k-{point}"));
        assert!(
            !call(&args(&k, &[]), Some(point)).status.success(),
            "{point}"
        );
        let o = call(&args(&k, &["--resume"]), None);
        assert!(
            o.status.success(),
            "{point}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for f in ["instances.parquet", "statistics.parquet"] {
            assert!(
                std::fs::read(whole.join(f)).unwrap() == std::fs::read(k.join(f)).unwrap(),
                "{point}: {f}"
            );
        }
    }

    // No history into a published result.
    let o = cryoslosh(
        &[
            "simulate",
            camp,
            "--out",
            whole.join("instances.parquet").to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    let o = cryoslosh(
        &[
            "simulate",
            camp,
            "--out",
            whole.join("extra.parquet").to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(!whole.join("extra.parquet").exists());

    // A symlink --out, and one under a file, get their own reasons (exit 2).
    #[cfg(unix)]
    {
        let link = root.join("link");
        std::os::unix::fs::symlink(&whole, &link).unwrap();
        let o = call(&args(&link, &["--force"]), None);
        assert_eq!(o.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&o.stderr).contains("symbolic link"));
    }
    let o = call(&args(&whole.join("run.json").join("sub"), &[]), None);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("is a file"));

    // Merge: an emptied manifest, a run.json whose counts disagree with the rows (manifest
    // re-hashed), a shard of another seed (named).
    let shard = |name: &str, spec: &str, seed: &str| {
        let d = root.join(name);
        let mut a = args(&d, &["--shard", spec]);
        let i = a.iter().position(|x| x == "--seed").unwrap();
        a[i + 1] = seed.to_string();
        assert!(call(&a, None).status.success());
        d
    };
    let s0 = shard("s0", "0/2", "2");
    let s1 = shard("s1", "1/2", "2");
    let other = shard("o1", "1/2", "3");
    let merge = |dirs: &[&Path]| {
        let mut a = vec!["merge".to_string()];
        a.extend(dirs.iter().map(|d| d.to_str().unwrap().to_string()));
        a.extend([
            "--out".to_string(),
            root.join("m").to_str().unwrap().to_string(),
        ]);
        call(&a, None)
    };
    let o = merge(&[&s0, &other]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cryoslosh.seed") && err.contains("o1"),
        "{err}"
    );
    let manifest = s1.join("manifest.json");
    let kept = std::fs::read(&manifest).unwrap();
    std::fs::write(&manifest, r#"{"files":{},"version":"x"}"#).unwrap();
    let o = merge(&[&s0, &s1]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does not list"));
    std::fs::write(&manifest, &kept).unwrap();
    if common::python_with("pyarrow") {
        let script = format!(
            "import json, hashlib\n\
             r = json.load(open('{0}/run.json')); r['diverged'] = 5\n\
             data = json.dumps(r).encode(); open('{0}/run.json', 'wb').write(data)\n\
             m = json.load(open('{0}/manifest.json'))\n\
             m['files']['run.json'] = {{'bytes': len(data), 'sha256': hashlib.sha256(data).hexdigest()}}\n\
             json.dump(m, open('{0}/manifest.json', 'w'))\n",
            s1.display()
        );
        let py = Command::new("python3")
            .args(["-c", &script])
            .output()
            .unwrap();
        assert!(
            py.status.success(),
            "{}",
            String::from_utf8_lossy(&py.stderr)
        );
        let o = merge(&[&s0, &s1]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains("run.json says diverged 5"), "{err}");
    }
    assert!(!root.join("m").exists());
    std::fs::remove_dir_all(root).ok();
}
