//! `vworks sweep` as a user runs it — the table streamed as rows finish, Ctrl-C and a
//! kill, the per-variant wall-time limit, checks before running, full disks, the units of
//! the table and the best, `--variables` with values, keeping only some variants' logs —
//! and every output of the CLI refusing to overwrite an input.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

fn vworks_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vworks"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .unwrap()
}

fn spawn_in(dir: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_vworks"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A fresh folder with a one-robot cell whose program never ends when its param
/// `endless` is 1, and a sweep file over `endless` with `values`.
fn sweep_dir(name: &str, values: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vworks-sweep-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(
        d.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap();
    std::fs::write(
        d.join("r1.wsl"),
        "param endless = 0;\nproc main() {\n    delay 1s;\n    while endless == 1 {\n        delay 1s;\n    }\n}\n",
    )
    .unwrap();
    std::fs::write(
        d.join("s.toml"),
        format!(
            "cell = \"cell.toml\"\n[[variable]]\npath = \"params.endless\"\nvalues = {values}\n"
        ),
    )
    .unwrap();
    d
}

/// The rows of a CSV table (header left out).
fn rows(csv: &str) -> Vec<String> {
    csv.lines().skip(1).map(str::to_string).collect()
}

fn signal(child: &Child, sig: &str) {
    let status = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

/// Variant 2 never ends. The rows before it are in the table while it runs (a kill
/// leaves them); Ctrl-C stops it at once, keeps them and exits 130.
#[cfg(unix)]
#[test]
fn rows_are_written_as_they_finish_and_ctrl_c_keeps_them() {
    let d = sweep_dir("sigint", "[0, 0, 1, 0]");
    let child = spawn_in(&d, &["sweep", "s.toml", "--jobs", "1", "-q"]);
    let seen = partial_rows_named(&d, "s.csv", 2);
    assert!(rows(&seen)[0].starts_with("0,0,completed,1,"), "{seen}");
    signal(&child, "-INT");
    let out = child.wait_with_output().unwrap();
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains("2 variants in") && err.contains("(interrupted)"),
        "{err}"
    );
    let table = std::fs::read_to_string(d.join("s.csv")).unwrap();
    let got: Vec<String> = rows(&table);
    assert_eq!(got.len(), 2, "{table}");
    assert!(got[1].starts_with("1,0,completed,1,"), "{table}");
    assert!(
        std::fs::read_to_string(d.join("s.html"))
            .unwrap()
            .contains("<table id=\"all\">")
    );
    assert!(text(&out.stdout).contains("variant 0: end_time 1"));
    // A kill leaves the rows done in the table being written.
    let child = spawn_in(&d, &["sweep", "s.toml", "--jobs", "1", "-q", "-o", "k.csv"]);
    let seen = partial_rows_named(&d, "k.csv", 2);
    signal(&child, "-KILL");
    let _ = child.wait_with_output();
    assert_eq!(rows(&seen).len(), 2, "{seen}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Waits (up to a generous minute) until the table `name` being written in `dir` holds
/// `n` rows; returns its text.
fn partial_rows_named(dir: &Path, name: &str, n: usize) -> String {
    for _ in 0..1200 {
        let partial = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| Some(e.ok()?.path()))
            .find(|p| {
                let f = p.file_name().unwrap_or_default().to_string_lossy();
                f.starts_with(&format!("{name}.")) && f.ends_with(".partial")
            });
        if let Some(text) = partial.and_then(|p| std::fs::read_to_string(p).ok())
            && rows(&text).len() >= n
        {
            return text;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    panic!("the table {name} never held {n} rows while the sweep ran");
}

/// With `--variant-timeout`, the endless variant is a `timeout` row and the sweep goes on.
#[test]
fn an_endless_variant_is_a_timeout_row() {
    let d = sweep_dir("timeout", "[0, 1, 0]");
    let out = vworks_in(&d, &["sweep", "s.toml", "--variant-timeout", "500ms", "-q"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("1 timed out"), "{err}");
    let table = std::fs::read_to_string(d.join("s.csv")).unwrap();
    let got = rows(&table);
    assert_eq!(got.len(), 3, "{table}");
    assert!(got[1].starts_with("1,1,timeout,"), "{table}");
    assert!(got[1].contains("variant timeout of 0.5 s"), "{table}");
    assert!(got[2].starts_with("2,0,completed,1,"), "{table}");
    let bad = vworks_in(&d, &["sweep", "s.toml", "--variant-timeout", "0s"]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(text(&bad.stderr).contains("--variant-timeout `0s` is not a time above 0"));
    let _ = std::fs::remove_dir_all(&d);
}

/// A wrong objective was found after every variant ran, and nothing was written: now it
/// is an error before the first variant. A sweep where no variant loads still writes its
/// table, with the reasons.
#[test]
fn the_objective_is_checked_first_and_the_table_always_written() {
    let d = sweep_dir("minimize", "[0, 0]");
    let out = vworks_in(&d, &["sweep", "s.toml", "--minimize", "cycle_time.r3"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--minimize: `cycle_time.r3` is not a numeric column of the table; choose one of variant, params.endless, end_time, cycle_time.r1, collisions, min_clearance"),
        "{err}"
    );
    assert!(!err.contains("variants in"), "nothing ran: {err}");
    let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
    assert_eq!(left.len(), 3, "nothing written: {left:?}");
    // Every variant invalid: the table says why, the exit is 0.
    std::fs::write(
        d.join("s.toml"),
        "cell = \"cell.toml\"\n[[variable]]\npath = \"cycle\"\nvalues = [\"1 furlong\", \"-4ms\"]\n",
    )
    .unwrap();
    let out = vworks_in(&d, &["sweep", "s.toml"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        text(&out.stdout),
        "no variant completed: 2 invalid; the best are ranked among the variants that completed without a collision: the rows' `error` says why the others did not complete\n"
    );
    let table = std::fs::read_to_string(d.join("s.csv")).unwrap();
    let got = rows(&table);
    assert_eq!(got.len(), 2, "{table}");
    assert!(
        got.iter()
            .all(|r| r.contains(",invalid,") && r.contains("cycle")),
        "{table}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A table on a full disk left a truncated file and said "check that its folder exists":
/// now it says so, keeps no partial file, and still prints the best variants; a log that
/// cannot be written fails the sweep.
#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_is_said_and_fails_the_sweep() {
    let d = sweep_dir("full", "[0, 0]");
    let out = vworks_in(&d, &["sweep", "s.toml", "-o", "/dev/full"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot write `/dev/full`: no space left on device"),
        "{err}"
    );
    assert!(!err.contains("check that its folder exists"), "{err}");
    assert!(
        text(&out.stdout).contains("variant 0: end_time 1"),
        "{}",
        text(&out.stdout)
    );
    // The logs: variant 1's is /dev/full.
    let logs = d.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    std::os::unix::fs::symlink("/dev/full", logs.join("variant-00001.mcap")).unwrap();
    let out = vworks_in(&d, &["sweep", "s.toml", "--keep-logs", "logs"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the logs of 1 variants could not be written"),
        "{err}"
    );
    let table = std::fs::read_to_string(d.join("s.csv")).unwrap();
    let got = rows(&table);
    assert!(got[0].contains(",completed,"), "{table}");
    assert!(
        got[1].contains(",error,") && got[1].contains("No space left on device"),
        "{table}"
    );
    assert!(
        std::fs::metadata(logs.join("variant-00000.mcap"))
            .unwrap()
            .len()
            > 0
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `report run.mcap -o run.mcap`, `sweep -o cell.toml`, `build x.wsl -o x.wsl` destroyed
/// their input: each is refused, by path, through `./` or a symlink, and the input stays.
#[test]
fn an_output_that_is_an_input_is_refused() {
    let d = sweep_dir("inputs", "[0]");
    let ok = vworks_in(&d, &["run", "cell.toml", "--log", "run.mcap"]);
    assert_eq!(ok.status.code(), Some(0), "{}", text(&ok.stderr));
    let log = std::fs::read(d.join("run.mcap")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink("r1.wsl", d.join("link.wsl")).unwrap();
    let cases: &[&[&str]] = &[
        &["build", "r1.wsl", "-o", "r1.wsl"],
        &["build", "r1.wsl", "-o", "./r1.wsl"],
        #[cfg(unix)]
        &["build", "r1.wsl", "-o", "link.wsl"],
        &["report", "run.mcap", "-o", "run.mcap"],
        &["report", "run.mcap", "-o", "./run.mcap"],
        &["sweep", "s.toml", "-o", "cell.toml"],
        &["sweep", "s.toml", "-o", "s.toml"],
        &["sweep", "s.toml", "--html", "./r1.wsl"],
        &["sweep", "s.toml", "-o", "t.csv", "--html", "t.csv"],
        &["run", "cell.toml", "--log", "r1.wsl"],
        &["run", "cell.toml", "--log", "./cell.toml"],
    ];
    let before: Vec<(String, Vec<u8>)> = ["r1.wsl", "cell.toml", "s.toml"]
        .iter()
        .map(|f| (f.to_string(), std::fs::read(d.join(f)).unwrap()))
        .collect();
    for args in cases {
        let out = vworks_in(&d, args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("writing it would destroy it"),
            "{args:?}: {err}"
        );
        for (f, bytes) in &before {
            assert_eq!(
                &std::fs::read(d.join(f)).unwrap(),
                bytes,
                "{args:?} changed {f}"
            );
        }
        assert_eq!(std::fs::read(d.join("run.mcap")).unwrap(), log, "{args:?}");
    }
    // Outputs elsewhere are written, with no temporary file left beside them.
    for args in [
        &["build", "r1.wsl", "-o", "r1.wslb"][..],
        &["report", "run.mcap", "-o", "run.html"],
        &["run", "cell.toml", "--log", "run.mcap"],
        &["sweep", "s.toml"],
    ] {
        let out = vworks_in(&d, args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{args:?}: {}",
            text(&out.stderr)
        );
    }
    let partial: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.ends_with(".partial"))
        .collect();
    assert!(partial.is_empty(), "{partial:?}");
    let _ = std::fs::remove_dir_all(&d);
}

/// `run --log /dev/full` removed the device (the failed log's "temporary file" was the
/// device itself, written in place): a device output is never replaced or removed.
#[cfg(target_os = "linux")]
#[test]
fn a_device_output_is_neither_replaced_nor_removed() {
    use std::os::unix::fs::FileTypeExt;
    let d = sweep_dir("device", "[0]");
    let is_device =
        || std::fs::symlink_metadata("/dev/full").is_ok_and(|m| m.file_type().is_char_device());
    assert!(is_device(), "/dev/full is not the device before the test");
    let ok = vworks_in(&d, &["run", "cell.toml", "--log", "run.mcap"]);
    assert_eq!(ok.status.code(), Some(0), "{}", text(&ok.stderr));
    for args in [
        &["run", "cell.toml", "--log", "/dev/full"][..],
        &["build", "r1.wsl", "-o", "/dev/full"],
        &["report", "run.mcap", "-o", "/dev/full"],
        &["sweep", "s.toml", "-o", "/dev/full"],
    ] {
        let out = vworks_in(&d, args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.to_lowercase().contains("no space left on device"),
            "{args:?}: {err}"
        );
        assert!(is_device(), "{args:?} replaced or removed /dev/full");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A fresh folder with `files` (name, text).
fn dir_with(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vworks-sweep-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    for (f, text) in files {
        std::fs::write(d.join(f), text).unwrap();
    }
    d
}

/// One robot whose program waits its param `wait` (1 s unless set): the run ends then.
const WAITING_CELL: &str = "cycle = \"8ms\"\n[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\nbase = { xyz = [\"650mm\", 0.1, \"0mm\"] }\n";
const WAITING_PROGRAM: &str = "param wait = 1s;\nproc main() {\n    delay wait;\n}\n";

/// `sweep --variables` listed names only: now each with its value, as the file writes it,
/// or the value it has without the file saying (marked).
#[test]
fn variables_are_listed_with_their_values() {
    let d = dir_with(
        "variables",
        &[("cell.toml", WAITING_CELL), ("r1.wsl", WAITING_PROGRAM)],
    );
    let out = vworks_in(&d, &["sweep", "--variables", "cell.toml"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let listed = text(&out.stdout);
    let lines: Vec<&str> = listed.lines().collect();
    for want in [
        "cycle = 8ms",
        "robot.r1.base.xyz.0 = 650mm",
        "robot.r1.base.xyz.1 = 0.1",
        "robot.r1.base.xyz.2 = 0mm",
        "robot.r1.base.rpy.2 = 0deg  (not in the file)",
        "robot.r1.params.wait = 1s  (not in the file)",
        "params.wait = 1s in r1's program  (not in the file)",
        "robot.r1.default_zone = fine  (not in the file)",
    ] {
        assert!(lines.contains(&want), "no `{want}` in:\n{listed}");
    }
    // Every line names a variable and a value.
    assert!(
        lines
            .iter()
            .all(|l| l.split_once(" = ").is_some_and(|(_, v)| !v.is_empty())),
        "{listed}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `robot.r2.base.xyz.0 = 0.5` for 500 mm: a variable written with a unit is shown in
/// it, in the table's header and values, in the best variants and on the page; the
/// objective may be named with or without its unit; the rate has three digits.
#[test]
fn results_keep_the_units_they_were_written_in() {
    let d = dir_with(
        "units",
        &[
            ("cell.toml", WAITING_CELL),
            ("r1.wsl", WAITING_PROGRAM),
            (
                "s.toml",
                "cell = \"cell.toml\"\n\
                 [[variable]]\npath = \"robot.r1.base.xyz.0\"\nvalues = [\"450mm\", 0.5]\n\
                 [[variable]]\npath = \"robot.r1.base.rpy.2\"\nrange = { from = \"0deg\", to = \"10deg\", steps = 3 }\n\
                 [[variable]]\npath = \"params.wait\"\nvalues = [\"1500ms\", \"1s\"]\n",
            ),
        ],
    );
    let out = vworks_in(
        &d,
        &[
            "sweep",
            "s.toml",
            "--best",
            "2",
            "--minimize",
            "end_time [s]",
        ],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let table = std::fs::read_to_string(d.join("s.csv")).unwrap();
    let mut lines = table.lines();
    assert_eq!(
        lines.next().unwrap(),
        "variant,robot.r1.base.xyz.0 [mm],robot.r1.base.rpy.2 [deg],params.wait [ms],outcome,end_time [s],cycle_time.r1 [s],collisions,min_clearance [m],error"
    );
    // The product: the last variable changes fastest. 0.5 m is 500 mm; 1 s is 1000 ms.
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 12, "{table}");
    let cells = |k: usize| rows.iter().map(|r| r[k]).collect::<Vec<_>>();
    assert_eq!(
        cells(1)[..7],
        ["450", "450", "450", "450", "450", "450", "500"]
    );
    assert_eq!(cells(2)[..6], ["0", "0", "5", "5", "10", "10"]);
    assert_eq!(cells(3)[..2], ["1500", "1000"]);
    assert_eq!(cells(5)[..2], ["1.5", "1"]);
    // The best: 1 s waits, smallest first (ties in variant order), in their units.
    let best = text(&out.stdout);
    assert_eq!(
        best,
        "best by end_time (completed, no collision):\n  \
         variant 1: end_time 1 s  (robot.r1.base.xyz.0 = 450mm, robot.r1.base.rpy.2 = 0deg, params.wait = 1000ms)\n  \
         variant 3: end_time 1 s  (robot.r1.base.xyz.0 = 450mm, robot.r1.base.rpy.2 = 5deg, params.wait = 1000ms)\n"
    );
    // The summary's rate: three significant digits (12 variants over the time it says).
    let summary = err.lines().find(|l| l.contains(" variants in ")).unwrap();
    let (seconds, rate) = summary
        .strip_prefix("12 variants in ")
        .and_then(|s| s.split_once(" s ("))
        .map(|(t, rest)| (t, rest.split(' ').next().unwrap()))
        .unwrap_or_else(|| panic!("{summary}"));
    // Decimals only below 100, and then three significant digits at most.
    let significant = rate
        .chars()
        .filter(char::is_ascii_digit)
        .skip_while(|c| *c == '0')
        .count();
    assert!(!rate.contains('.') || significant <= 3, "{summary}");
    let (seconds, rate): (f64, f64) = (seconds.parse().unwrap(), rate.parse().unwrap());
    // The time is said to 10 ms: the rate lies between 12 over its ends (± its rounding).
    let (slow, fast) = (12.0 / (seconds + 0.005), 12.0 / (seconds - 0.005).max(1e-9));
    assert!(
        rate >= slow * 0.995 - 0.5 && rate <= fast * 1.005 + 0.5,
        "{summary}"
    );
    // JSON lines: the same keys as the CSV's header.
    let out = vworks_in(&d, &["sweep", "s.toml", "-o", "t.jsonl", "-q"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let first = std::fs::read_to_string(d.join("t.jsonl")).unwrap();
    assert!(
        first.starts_with("{\"variant\":0,\"robot.r1.base.xyz.0 [mm]\":450.0,\"robot.r1.base.rpy.2 [deg]\":0.0,\"params.wait [ms]\":1500.0,\"outcome\":\"completed\",\"end_time [s]\":1.5,"),
        "{first}"
    );
    // The page names the columns with their units.
    let page = std::fs::read_to_string(d.join("s.html")).unwrap();
    assert!(page.contains("robot.r1.base.xyz.0 [mm]") && page.contains("id=\"colorbar\""));
    // A unit that is not the column's is no column.
    let out = vworks_in(&d, &["sweep", "s.toml", "--minimize", "end_time [ms]"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("--minimize: `end_time [ms]` is not a numeric column"),
        "{}",
        text(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The files of a logs folder, sorted.
fn logs_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
        .collect();
    names.sort();
    names
}

/// `--keep-logs` kept every variant's log: `--keep-logs-variants` writes only the listed
/// ones, `--keep-logs-best N` keeps the N best by the objective (and the listed).
#[test]
fn keep_logs_can_keep_only_some_variants() {
    let d = dir_with(
        "keep",
        &[
            ("cell.toml", WAITING_CELL),
            ("r1.wsl", WAITING_PROGRAM),
            (
                "s.toml",
                "cell = \"cell.toml\"\n[[variable]]\npath = \"params.wait\"\nvalues = [\"3s\", \"1s\", \"2s\", \"500ms\", \"4s\", \"2500ms\"]\n",
            ),
        ],
    );
    let log = |i: usize| format!("variant-{i:05}.mcap");
    let out = vworks_in(
        &d,
        &[
            "sweep",
            "s.toml",
            "-q",
            "--keep-logs",
            "a",
            "--keep-logs-variants",
            "4,0-1",
        ],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert_eq!(logs_in(&d.join("a")), [log(0), log(1), log(4)]);
    assert!(
        err.contains("kept in a the logs of variants 4,0-1"),
        "{err}"
    );
    // The best 2 by end_time: 500ms (3) and 1s (1); with variant 5 listed too.
    let out = vworks_in(
        &d,
        &[
            "sweep",
            "s.toml",
            "-q",
            "--jobs",
            "2",
            "--keep-logs",
            "b",
            "--keep-logs-best",
            "2",
            "--keep-logs-variants",
            "5",
        ],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert_eq!(logs_in(&d.join("b")), [log(1), log(3), log(5)]);
    assert!(
        err.contains(
            "kept in b the logs of the 2 best variants by end_time (3, 1) and of variants 5"
        ),
        "{err}"
    );
    // Wrong lists and numbers are errors before anything runs.
    for (args, says) in [
        (
            &["--keep-logs", "c", "--keep-logs-variants", "2,x"][..],
            "--keep-logs-variants: `x` is not a variant number",
        ),
        (
            &["--keep-logs", "c", "--keep-logs-variants", "6"],
            "--keep-logs-variants: variant 6 is not one of this sweep's 6 (0 to 5)",
        ),
        (&["--keep-logs-best", "2"], "--keep-logs"),
        (
            &["--keep-logs", "c", "--keep-logs-best", "0"],
            "--keep-logs-best",
        ),
    ] {
        let out = vworks_in(&d, &[&["sweep", "s.toml"][..], args].concat());
        let err = text(&out.stderr);
        assert_ne!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("variants in"), "{args:?} ran: {err}");
    }
    assert!(!d.join("c").exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// With `--keep-logs-best`, Ctrl-C leaves the best so far: the log of the variant that
/// was stopped (it has no row) goes with those that were not among the best.
#[cfg(unix)]
#[test]
fn keep_logs_best_after_ctrl_c_keeps_only_the_best() {
    let d = sweep_dir("keepint", "[0, 0, 1, 0]");
    let child = spawn_in(
        &d,
        &[
            "sweep",
            "s.toml",
            "--jobs",
            "1",
            "-q",
            "--keep-logs",
            "logs",
            "--keep-logs-best",
            "1",
        ],
    );
    partial_rows_named(&d, "s.csv", 2);
    // Variant 2 (endless) is running: its log is being written, beside its name until
    // the run ends (`variant-00002.mcap.PID.partial`).
    let writing = || {
        std::fs::read_dir(d.join("logs")).is_ok_and(|mut files| {
            files.any(|f| {
                f.is_ok_and(|f| {
                    let name = f.file_name().to_string_lossy().into_owned();
                    name.starts_with("variant-00002.mcap.") && name.ends_with(".partial")
                })
            })
        })
    };
    for _ in 0..1200 {
        if writing() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert!(writing());
    signal(&child, "-INT");
    let out = child.wait_with_output().unwrap();
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    // Variants 0 and 1 both end at 1 s: the earlier is the best.
    assert_eq!(logs_in(&d.join("logs")), ["variant-00000.mcap"], "{err}");
    assert!(
        err.contains("kept in logs the logs of the 1 best variants by end_time (0)"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `vworks sweep FOLDER` said "it is a folder": it runs the folder's sweep file (its
/// sweep.toml, else its one .toml with `[[variable]]`s) as `run` runs a cell's folder,
/// writing the table beside it; a workcell given to `sweep` names the sweep file beside it.
#[test]
fn a_folder_is_swept_by_its_sweep_file() {
    let sweep =
        "cell = \"cell.toml\"\n[[variable]]\npath = \"params.wait\"\nvalues = [\"1s\", \"2s\"]\n";
    let d = dir_with(
        "folder",
        &[
            ("cell.toml", WAITING_CELL),
            ("r1.wsl", WAITING_PROGRAM),
            ("waits.toml", sweep),
        ],
    );
    let out = vworks_in(&d, &["sweep", ".", "-q"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("wrote ./waits.csv and ./waits.html"), "{err}");
    assert_eq!(
        rows(&std::fs::read_to_string(d.join("waits.csv")).unwrap()).len(),
        2
    );
    // The workcell given instead: the sweep file beside it.
    let out = vworks_in(&d, &["sweep", "cell.toml"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("`cell.toml` is a workcell, but `vworks sweep` takes a sweep file: one that names a workcell and the values to vary; the sweep file beside it: `vworks sweep waits.toml`"),
        "{err}"
    );
    // A sweep.toml is the folder's sweep file, whatever else is there.
    std::fs::write(d.join("sweep.toml"), sweep.replace("2s", "3s")).unwrap();
    let out = vworks_in(d.parent().unwrap(), &["sweep", d.to_str().unwrap(), "-q"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let table = std::fs::read_to_string(d.join("sweep.csv")).unwrap();
    assert!(table.starts_with("variant,params.wait [s],"), "{table}");
    assert!(table.contains("\n1,3,completed,3,"), "{table}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A zone of `"fine"`, `"10mm"` showed `fine`, 0.01 under no unit, and one `"0.5cm"` (no
/// unit vworks knows) turned the base's column into metres: a word or an invalid value is
/// shown as written, the others in the unit they were written in, in the table and the best.
#[test]
fn a_word_or_an_invalid_value_keeps_the_column_in_its_unit() {
    let d = dir_with(
        "words",
        &[
            ("cell.toml", WAITING_CELL),
            ("r1.wsl", WAITING_PROGRAM),
            (
                "s.toml",
                "cell = \"cell.toml\"\n\
                 [[variable]]\npath = \"robot.r1.default_zone\"\nvalues = [\"fine\", \"10mm\"]\n\
                 [[variable]]\npath = \"robot.r1.base.xyz.0\"\nvalues = [\"650mm\", \"0.5cm\", \"700mm\"]\n",
            ),
        ],
    );
    let out = vworks_in(&d, &["sweep", "s.toml", "--best", "2", "-q"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let table = std::fs::read_to_string(d.join("s.csv")).unwrap();
    let lines: Vec<&str> = table.lines().collect();
    assert!(
        lines[0]
            .starts_with("variant,robot.r1.default_zone [mm],robot.r1.base.xyz.0 [mm],outcome,"),
        "{table}"
    );
    let starts: Vec<String> = lines[1..]
        .iter()
        .map(|l| l.split(',').take(4).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(
        starts,
        [
            "0,fine,650,completed",
            "1,fine,0.5cm,invalid",
            "2,fine,700,completed",
            "3,10,650,completed",
            "4,10,0.5cm,invalid",
            "5,10,700,completed",
        ],
        "{table}"
    );
    assert!(lines[2].contains("`0.5cm` is not a quantity"), "{table}");
    assert_eq!(
        text(&out.stdout),
        "best by end_time (completed, no collision):\n  \
         variant 0: end_time 1 s  (robot.r1.default_zone = fine, robot.r1.base.xyz.0 = 650mm)\n  \
         variant 2: end_time 1 s  (robot.r1.default_zone = fine, robot.r1.base.xyz.0 = 700mm)\n"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Every variant stopped at `until` said "no variant completed without a collision": now
/// the summary says what became of them and what to do.
#[test]
fn no_best_says_what_became_of_the_variants() {
    let d = dir_with(
        "until",
        &[
            ("cell.toml", WAITING_CELL),
            ("r1.wsl", WAITING_PROGRAM),
            (
                "s.toml",
                "cell = \"cell.toml\"\nuntil = \"500ms\"\n[[variable]]\npath = \"params.wait\"\nvalues = [\"1s\", \"2s\", \"3s\", \"4s\"]\n",
            ),
        ],
    );
    let out = vworks_in(&d, &["sweep", "s.toml", "-q"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        text(&out.stdout),
        "no variant completed: 4 stopped at `until` (500ms); the best are ranked among the variants that completed without a collision: raise `until` in s.toml (or remove it) for them to complete\n"
    );
    // Each outcome is said, with what to do about it.
    std::fs::write(
        d.join("s.toml"),
        "cell = \"cell.toml\"\nuntil = \"1500ms\"\n[[variable]]\npath = \"params.wait\"\nvalues = [\"2s\", \"3s\", \"0.5cm\"]\n",
    )
    .unwrap();
    let out = vworks_in(&d, &["sweep", "s.toml", "-q"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        text(&out.stdout),
        "no variant completed: 2 stopped at `until` (1.5s), 1 invalid; the best are ranked among the variants that completed without a collision: raise `until` in s.toml (or remove it) for them to complete; the rows' `error` says why the others did not complete\n"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `until = 0` is the cell's start, from `run --until 0s` and in a sweep file alike (a
/// sweep refused it while `run` and Python's `Cell.run` took it); a time before the start
/// is refused by both.
#[test]
fn until_zero_is_the_start_in_run_and_in_a_sweep() {
    let d = dir_with(
        "until-zero",
        &[
            ("cell.toml", WAITING_CELL),
            ("r1.wsl", WAITING_PROGRAM),
            (
                "s.toml",
                "cell = \"cell.toml\"\nuntil = \"0s\"\n[[variable]]\npath = \"params.wait\"\nvalues = [\"1s\", \"2s\"]\n",
            ),
        ],
    );
    let out = vworks_in(&d, &["run", "cell.toml", "--until", "0s", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (&json["outcome"], &json["end_time_ns"]),
        (&"until".into(), &0.into())
    );
    let out = vworks_in(&d, &["sweep", "s.toml", "-q", "-o", "t.csv"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let table = std::fs::read_to_string(d.join("t.csv")).unwrap();
    let outcomes: Vec<String> = rows(&table)
        .iter()
        .map(|r| r.split(',').nth(2).unwrap_or_default().to_string())
        .collect();
    assert_eq!(outcomes, ["until", "until"], "{table}");
    std::fs::write(
        d.join("s.toml"),
        "cell = \"cell.toml\"\nuntil = \"-1s\"\n[[variable]]\npath = \"params.wait\"\nvalues = [\"1s\"]\n",
    )
    .unwrap();
    let out = vworks_in(&d, &["sweep", "s.toml", "-q", "-o", "t.csv"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("not a time to stop at"),
        "{}",
        text(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&d);
}
