//! The `vworks` binary as a user runs it: exit codes, messages, files written.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;
use std::process::{Command, Output};

fn vworks(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vworks"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .unwrap_or_else(|e| panic!("cannot run vworks: {e}"))
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vworks-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap_or_else(|e| panic!("{e}"));
    d
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

const THREE_ERRORS: &str = "global parts = 0;
proc main() {
    delay 2;
    parts = prats + 1;
    var a = 90deg + 10mm;
}
";

#[test]
fn check_prints_every_error_and_exits_1() {
    let d = temp_dir("check");
    let f = d.join("three.wsl");
    std::fs::write(&f, THREE_ERRORS).unwrap_or_else(|e| panic!("{e}"));
    let out = vworks(&["check", f.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    for code in ["error[E0021]", "error[E0010]"] {
        assert!(err.contains(code), "{err}");
    }
    assert_eq!(err.matches("error[").count(), 3, "{err}");
    assert!(err.contains("three.wsl:3:11"), "{err}");
    assert!(err.contains("help: write 2s"), "{err}");
    assert!(err.contains("3 errors"), "{err}");
}

#[test]
fn check_accepts_good_files_and_several_at_once() {
    let d = temp_dir("good");
    let a = d.join("a.wsl");
    let b = d.join("b.wsl");
    std::fs::write(&a, "proc main() { delay 1s; }\n").unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(&b, "global g = 0;\nproc main() { g = 1; }\n").unwrap_or_else(|e| panic!("{e}"));
    let out = vworks(&[
        "check",
        a.to_str().unwrap_or_default(),
        b.to_str().unwrap_or_default(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("checked 2 files: 0 errors, 0 warnings"));
}

#[test]
fn build_then_disasm_shows_source_beside_code() {
    let d = temp_dir("build");
    let f = d.join("r1.wsl");
    std::fs::write(
        &f,
        "global parts = 0;\nproc main() {\n    parts = parts + 1;\n}\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let wslb = d.join("r1.wslb");
    let out = vworks(&[
        "build",
        f.to_str().unwrap_or_default(),
        "-o",
        wslb.to_str().unwrap_or_default(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(wslb.exists());
    let out = vworks(&["disasm", wslb.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let listing = text(&out.stdout);
    assert!(listing.contains("StoreGlobal   g0 (parts)"), "{listing}");
    assert!(listing.contains("| parts = parts + 1;"), "{listing}");
    // A .wsl file is compiled and listed directly.
    let out = vworks(&["disasm", f.to_str().unwrap_or_default()]);
    assert_eq!(text(&out.stdout), listing);
}

#[test]
fn a_task_of_several_rapid_modules_is_checked_built_and_listed_as_one_program() {
    let d = temp_dir("task");
    let main = d.join("main.mod");
    let tools = d.join("tools.mod");
    std::fs::write(
        &main,
        "MODULE MainMod\n  PERS num nParts := 0;\n  PROC main()\n    Pick;\n  ENDPROC\nENDMODULE\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(
        &tools,
        "MODULE Tools\n  PROC Pick()\n    WaitTime 0.5;\n    Incr nParts;\n  ENDPROC\nENDMODULE\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let (m, t) = (
        main.to_str().unwrap_or_default(),
        tools.to_str().unwrap_or_default(),
    );
    // One by one, each module misses the other's names.
    let out = vworks(&["check", m, t]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("unknown instruction or procedure `Pick`"),
        "{err}"
    );
    assert!(err.contains("unknown name `nParts`"), "{err}");
    // As one task they compile.
    let out = vworks(&["check", "--task", m, t]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("checked 2 files: 0 errors, 0 warnings"));
    // Built into one module whose listing names each file's lines.
    let wslb = d.join("task.wslb");
    let out = vworks(&["build", m, t, "-o", wslb.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let out = vworks(&["disasm", wslb.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let listing = text(&out.stdout);
    assert!(listing.contains("; tools.mod:3:5"), "{listing}");
    assert!(listing.contains("| WaitTime 0.5;"), "{listing}");
    assert!(listing.contains("; main.mod:4:5"), "{listing}");
    assert!(listing.contains("| Pick;"), "{listing}");
    let out = vworks(&["disasm", m, t]);
    assert_eq!(text(&out.stdout), listing);
    // A bytecode file is listed alone.
    let out = vworks(&["disasm", wslb.to_str().unwrap_or_default(), t]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("list it alone"));
}

#[test]
fn bad_inputs_are_errors_with_the_file_named() {
    let d = temp_dir("bad");
    let missing = d.join("missing.wsl");
    let out = vworks(&["check", missing.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("cannot read"),
        "{}",
        text(&out.stderr)
    );
    assert!(text(&out.stderr).contains("missing.wsl"));

    let corrupt = d.join("corrupt.wslb");
    std::fs::write(&corrupt, b"WSLB\x05\x00\x00\x00garbage").unwrap_or_else(|e| panic!("{e}"));
    let out = vworks(&["disasm", corrupt.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("corrupt.wslb") && err.contains("malformed bytecode"),
        "{err}"
    );

    let bad = d.join("bad.wsl");
    std::fs::write(&bad, "proc main() { move_j; }").unwrap_or_else(|e| panic!("{e}"));
    let out = vworks(&["build", bad.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("not built"));
    assert!(!d.join("bad.wslb").exists());
}

fn workcell(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../workcells")
        .join(name)
        .join("cell.toml")
        .display()
        .to_string()
}

#[test]
fn run_prints_a_summary_and_exits_by_outcome() {
    let out = vworks(&["run", &workcell("handoff")]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    // The programs' two `log` lines as they happened (r2's at 35.4 s, r1's last, at its
    // end), then the summary.
    let lines: Vec<&str> = s.lines().collect();
    assert!(lines[0].starts_with("[35.442 s] r2: "), "{s}");
    assert!(lines[1].starts_with("[46.491 s] r1: r1 done"), "{s}");
    assert_eq!(lines[2], "cell handoff: completed at 46.491 s", "{s}");
    assert!(
        s.contains("r1") && s.contains("ended at") && s.contains("globals: handed=3"),
        "{s}"
    );
    // A collision stop and a deadlock exit with 1.
    assert_eq!(vworks(&["run", &workcell("crash")]).status.code(), Some(1));
    let out = vworks(&["run", &workcell("deadlock")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stdout).contains("r1 waits for the signal `r2_ready`"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn run_json_has_the_contracts_fields() {
    let out = vworks(&["run", &workcell("crash"), "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", text(&out.stdout)));
    assert_eq!(v["outcome"], "collision");
    assert!(v["end_time_ns"].as_i64().unwrap_or(0) > 0);
    let (queries, cycles) = (v["collision_queries"].as_f64(), v["cycles"].as_f64());
    let per_cycle = v["queries_per_cycle"].as_f64();
    assert!(
        matches!((queries, cycles, per_cycle), (Some(q), Some(c), Some(p)) if c > 0.0 && (q / c - p).abs() < 1e-9),
        "{v}"
    );
    for key in [
        "name",
        "moving_ns",
        "waiting_ns",
        "idle_ns",
        "motions",
        "end_time_ns",
    ] {
        assert!(v["robots"][0].get(key).is_some(), "robots[0].{key}");
    }
    for key in ["time_ns", "a", "b", "depth_m"] {
        assert!(v["collisions"][0].get(key).is_some(), "collisions[0].{key}");
    }
    assert!(v["warnings"].is_array() && v["errors"].is_array() && v["globals"].is_object());
    let out = vworks(&["run", &workcell("deadlock"), "--json"]);
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(v["outcome"], "deadlock");
    for key in ["kind", "message", "robot", "file", "line", "col"] {
        assert!(v["errors"][0].get(key).is_some(), "errors[0].{key}");
    }
    // Globals are JSON values of their type, not text.
    assert_eq!(v["globals"]["gate_open"], false);
}

#[test]
fn run_until_and_trace() {
    let out = vworks(&["run", &workcell("handoff"), "--until", "2s", "--trace-ns"]);
    assert_eq!(out.status.code(), Some(0));
    let s = text(&out.stdout);
    assert!(
        s.lines()
            .next()
            .is_some_and(|l| l.starts_with("0 r1 motion_start move_j")),
        "{s}"
    );
    assert!(s.lines().all(|l| {
        l.split(' ')
            .next()
            .and_then(|t| t.parse::<i64>().ok())
            .is_some_and(|t| t <= 2_000_000_000)
    }));
    // --trace: the same events, times and durations in seconds (`1.3 s` for 1300000000).
    let out = vworks(&["run", &workcell("handoff"), "--until", "2s", "--trace"]);
    assert_eq!(out.status.code(), Some(0));
    let people = text(&out.stdout);
    assert_eq!(people.lines().count(), s.lines().count());
    for (ns, sec) in s.lines().zip(people.lines()) {
        let (t_ns, rest_ns) = ns.split_once(' ').unwrap();
        let (t_s, rest_s) = sec.split_once(" s ").unwrap();
        let t_ns: i64 = t_ns.parse().unwrap();
        let t_s: f64 = t_s.parse().unwrap();
        assert!((t_s * 1e9 - t_ns as f64).abs() < 0.5, "{ns} / {sec}");
        // Everything else the same, but for durations and deadlines.
        if let Some((before, after)) = rest_ns.split_once("duration=") {
            let (d_ns, tail) = after.split_once(' ').unwrap();
            let d: i64 = d_ns.parse().unwrap();
            let expected = if d % 1_000_000_000 == 0 {
                format!("{}duration={} s {tail}", before, d / 1_000_000_000)
            } else {
                let frac = format!("{:09}", d % 1_000_000_000);
                let frac = frac.trim_end_matches('0');
                format!("{before}duration={}.{frac} s {tail}", d / 1_000_000_000)
            };
            assert_eq!(rest_s, expected);
        } else {
            assert_eq!(rest_s, rest_ns);
        }
    }
    assert!(people.contains(" duration=1.031315653 s "), "{people}");
    assert!(people.contains(" duration=0 s "), "{people}");
    // The summary is not dropped: it follows on stderr (a pipe gets the trace alone).
    let err = text(&out.stderr);
    assert!(err.starts_with("cell handoff: until at 2.000 s\n"), "{err}");
    assert!(!people.contains("cell handoff"), "{people}");
    // A trace and one JSON object cannot share stdout: asking for both is a usage error.
    let both = vworks(&["run", &workcell("handoff"), "--trace", "--json"]);
    assert_eq!(both.status.code(), Some(2));
    assert!(text(&both.stderr).contains("cannot be used with '--json'"));
    let out = vworks(&["run", &workcell("handoff"), "--until", "2 parsecs"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("not a time"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn ctrl_c_finishes_the_log() {
    let d = temp_dir("sigint");
    let log = d.join("run.mcap");
    // A cell that would run for hours of simulated time (minutes of wall time), so the
    // signal surely arrives while it runs.
    std::fs::write(
        d.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(
        d.join("r1.wsl"),
        "proc main() {\n    var n = 0;\n    while n < 100000 {\n        move_j joints(0deg, 0deg, 0deg, 0deg, 30deg, 0deg);\n        move_j joints(90deg, 0deg, 0deg, 0deg, 30deg, 0deg);\n        n = n + 1;\n    }\n}\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let cell = d.join("cell.toml");
    let child = Command::new(env!("CARGO_BIN_EXE_vworks"))
        .args([
            "run",
            cell.to_str().unwrap_or_default(),
            "--log",
            log.to_str().unwrap_or_default(),
        ])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{e}"));
    std::thread::sleep(std::time::Duration::from_millis(400));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(status.success());
    let out = child.wait_with_output().unwrap_or_else(|e| panic!("{e}"));
    let s = text(&out.stdout);
    assert_eq!(out.status.code(), Some(130), "{s}");
    assert!(s.contains("interrupted at"), "{s}");
    // The file is finished: a summary, and every message readable.
    let bytes = std::fs::read(&log).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        mcap::Summary::read(&bytes)
            .unwrap_or_else(|e| panic!("{e}"))
            .is_some()
    );
    let n = mcap::MessageStream::new(&bytes)
        .unwrap_or_else(|e| panic!("{e}"))
        .filter(|m| m.is_ok())
        .count();
    assert!(n > 0);
}

#[test]
fn a_closed_stdout_ends_quietly() {
    // `vworks disasm big.wsl | head -1`: far more output than a pipe holds.
    let dir = temp_dir("pipe");
    let body = "    delay 1s;\n".repeat(5000);
    std::fs::write(dir.join("big.wsl"), format!("proc main() {{\n{body}}}\n")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_vworks"))
        .args(["disasm", dir.join("big.wsl").to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = text(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(out.status.code(), Some(141), "{err}");
}

#[test]
fn a_log_cut_short_still_gives_what_was_written() {
    // What a hard kill leaves: the file up to some byte, no summary, no footer.
    let dir = temp_dir("cut");
    let log = dir.join("run.mcap");
    let run = vworks(&["run", &workcell("handoff"), "--log", log.to_str().unwrap()]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let full = std::fs::read(&log).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &full[..full.len() / 2]).unwrap();
    let all = vworks(&["log", "events", log.to_str().unwrap()]);
    let part = vworks(&["log", "events", cut.to_str().unwrap()]);
    assert_eq!(part.status.code(), Some(1));
    let warning = text(&part.stderr);
    assert!(
        warning.contains("unfinished") && warning.contains("mcap recover"),
        "{warning}"
    );
    let (all, part) = (text(&all.stdout), text(&part.stdout));
    assert!(
        all.starts_with(&part),
        "the events read are the run's first ones"
    );
    let n = part.lines().count();
    assert!(
        n > 20 && n < all.lines().count(),
        "{n} events survive the cut"
    );
}

/// Names read from a log (robots, topics) reached the terminal raw: an escape sequence in
/// a robot's name drove it in `log events`. They are escaped as log texts are.
#[test]
fn names_from_a_log_are_escaped() {
    let dir = temp_dir("escaped-names");
    std::fs::write(
        dir.join("cell.toml"),
        "name = \"c\"\n[[robot]]\nname = \"r\\u001b[31m1\"\nmodel = \"turntable\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap();
    std::fs::write(dir.join("r1.wsl"), "proc main() { log \"hi\"; }\n").unwrap();
    let log = dir.join("run.mcap");
    let cell = dir.join("cell.toml");
    let run = vworks(&[
        "run",
        cell.to_str().unwrap(),
        "--log",
        log.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let events = vworks(&["log", "events", log.to_str().unwrap()]);
    let out = text(&events.stdout);
    assert!(
        out.contains("0 r\\u{1b}[31m1 log \"hi\" r1.wsl:1:15"),
        "{out}"
    );
    assert!(!out.contains('\u{1b}'), "{out:?}");
    // A log written by another program, with an escape in a topic's name.
    let other = dir.join("other.mcap");
    let mut mcap = mcap::WriteOptions::new()
        .create(std::io::BufWriter::new(
            std::fs::File::create(&other).unwrap(),
        ))
        .unwrap();
    let schema = mcap.add_schema("raw", "", &[]).unwrap();
    let channel = mcap
        .add_channel(schema, "/x\u{1b}]0;owned\u{7}", "", &Default::default())
        .unwrap();
    let header = mcap::records::MessageHeader {
        channel_id: channel,
        sequence: 0,
        log_time: 0,
        publish_time: 0,
    };
    mcap.write_to_known_channel(&header, b"1").unwrap();
    mcap.finish().unwrap();
    drop(mcap);
    let info = vworks(&["log", "info", other.to_str().unwrap()]);
    let out = text(&info.stdout);
    assert!(out.contains("/x\\u{1b}]0;owned\\u{7}"), "{out}");
    assert!(!out.contains('\u{1b}') && !out.contains('\u{7}'), "{out:?}");
}

/// `vworks view` wrote its page to `$TMPDIR/vworks-view/<log>.html`: another local user
/// who made that folder first (or a link there) could overwrite the user's files or swap
/// the page. The page goes to a new folder of the user's own (mode 0700), created
/// exclusively: what is planted at the old path is neither followed nor written.
#[cfg(unix)]
#[test]
fn view_writes_its_page_in_a_private_folder_of_its_own() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = temp_dir("view-private");
    std::fs::write(
        dir.join("cell.toml"),
        "name = \"c\"\n[[robot]]\nname = \"r1\"\nmodel = \"turntable\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap();
    std::fs::write(dir.join("r1.wsl"), "proc main() { log \"hi\"; }\n").unwrap();
    let log = dir.join("run.mcap");
    let cell = dir.join("cell.toml");
    let run = vworks(&[
        "run",
        cell.to_str().unwrap(),
        "--log",
        log.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    // The planted folder: the old path links to the victim's folder, which holds a file of
    // the page's name.
    let tmp = dir.join("tmp");
    let victim = dir.join("victim");
    std::fs::create_dir_all(&tmp).unwrap();
    std::fs::create_dir_all(&victim).unwrap();
    std::fs::write(victim.join("run.html"), "precious").unwrap();
    std::os::unix::fs::symlink(&victim, tmp.join("vworks-view")).unwrap();
    let view = || {
        Command::new(env!("CARGO_BIN_EXE_vworks"))
            .args(["view", log.to_str().unwrap()])
            .env("TMPDIR", &tmp)
            .env_remove("BROWSER")
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap()
    };
    let out = view();
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        std::fs::read_to_string(victim.join("run.html")).unwrap() == "precious",
        "the victim's file was overwritten through the planted link"
    );
    assert_eq!(
        std::fs::read_dir(&victim).unwrap().count(),
        1,
        "nothing else written there"
    );
    let page = PathBuf::from(text(&out.stdout).trim());
    assert_eq!(page.file_name().unwrap(), "run.html");
    let folder = page.parent().unwrap();
    assert_eq!(
        folder.parent().unwrap(),
        tmp.as_path(),
        "{}",
        page.display()
    );
    assert_ne!(folder, tmp.join("vworks-view"));
    let meta = std::fs::symlink_metadata(folder).unwrap();
    assert!(meta.is_dir(), "a folder, not a link");
    assert_eq!(meta.permissions().mode() & 0o777, 0o700);
    assert!(std::fs::read_to_string(&page).unwrap().contains("<html"));
    // A second view makes a folder of its own again.
    let again = view();
    assert!(again.status.success(), "{}", text(&again.stderr));
    let second = PathBuf::from(text(&again.stdout).trim());
    assert_ne!(second.parent(), page.parent());
}

#[test]
fn a_file_that_is_not_a_log_is_an_error() {
    let dir = temp_dir("notlog");
    let f = dir.join("notes.mcap");
    std::fs::write(&f, "hello").unwrap();
    let out = vworks(&["log", "info", f.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("notes.mcap: not an MCAP file"), "{err}");
    assert!(text(&out.stdout).is_empty());
}

#[cfg(target_os = "linux")]
#[test]
fn a_log_that_cannot_be_written_fails_the_run_and_says_why() {
    let out = vworks(&["run", &workcell("handoff"), "--log", "/dev/full"]);
    assert_eq!(out.status.code(), Some(1));
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(stdout.contains("completed at 46.491 s"), "{stdout}");
    assert!(stdout.contains("log /dev/full: not written"), "{stdout}");
    assert!(
        stderr.contains("cannot write the log `/dev/full`") && stderr.contains("No space left"),
        "{stderr}"
    );
    let out = vworks(&[
        "run",
        &workcell("handoff"),
        "--log",
        "/nonexistent-dir/run.mcap",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("/nonexistent-dir/run.mcap"),
        "{}",
        text(&out.stderr)
    );
}

/// A byte that is not UTF-8 gave an error with no line: now the file, line and column.
#[test]
fn a_program_that_is_not_utf8_is_an_error_at_its_line() {
    let d = temp_dir("not-utf8");
    let p = d.join("latin1.wsl");
    // "café" in Latin-1 on line 2, column 11.
    std::fs::write(&p, b"proc main() {\n    log \"caf\xe9\";\n}\n").unwrap();
    let out = vworks(&["check", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains(
            "latin1.wsl: line 2, column 13: byte 0xE9 is not UTF-8 text; save the file as UTF-8"
        ),
        "{err}"
    );
    // The same through a workcell.
    std::fs::write(
        d.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nmodel = \"turntable\"\nprogram = \"latin1.wsl\"\n",
    )
    .unwrap();
    let out = vworks(&["run", d.join("cell.toml").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("line 2, column 13: byte 0xE9"), "{err}");
}

/// RAPID modules as controllers and RobotStudio write them, in Latin-1 (issue 31): a file
/// that is not UTF-8 is read as ISO-8859-1, each byte one character, so every position is
/// the file's own. A module with an accented comment and string checks and runs (its
/// `TPWrite` logs the "é"); an error after an "é" on its line is at the column that counts
/// that byte as one character (column 31, by hand).
#[test]
fn a_rapid_module_in_latin1_is_read_as_latin1() {
    let d = temp_dir("latin1-rapid");
    let ok = d.join("r1.mod");
    std::fs::write(
        &ok,
        b"MODULE r1\n    ! posici\xf3n de reposo\n    CONST string s := \"caf\xe9\";\n    PROC main()\n        TPWrite s;\n    ENDPROC\nENDMODULE\n",
    )
    .unwrap();
    let out = vworks(&["check", ok.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    std::fs::write(
        d.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nmodel = \"turntable\"\nprogram = \"r1.mod\"\n",
    )
    .unwrap();
    let out = vworks(&["run", d.join("cell.toml").to_str().unwrap(), "--trace"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("log \"café\""),
        "{}",
        text(&out.stdout)
    );
    let bad = d.join("bad.mod");
    std::fs::write(
        &bad,
        b"MODULE bad\n    ! posici\xf3n\n    PROC main()\n        WaitTime 1;\n        TPWrite \"\xe9\"; WaitTime qq;\n    ENDPROC\nENDMODULE\n",
    )
    .unwrap();
    let out = vworks(&["check", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("bad.mod:5:31"), "{err}");
    assert!(err.contains("TPWrite \"é\"; WaitTime qq;"), "{err}");
}

/// `package://` meshes are found through ROS_PACKAGE_PATH (after the workcell's
/// `package_path`), as a ROS-Industrial user expects.
#[test]
fn package_meshes_are_found_through_ros_package_path() {
    let d = temp_dir("ros-package-path");
    let share = d.join("ros/share");
    std::fs::create_dir_all(share.join("my_robot/meshes")).unwrap();
    let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0 0.1 0\nvertex 0 0 0.1\nendloop\nendfacet\nendsolid t\n";
    std::fs::write(share.join("my_robot/meshes/base.stl"), stl).unwrap();
    let cell = d.join("cell");
    std::fs::create_dir_all(&cell).unwrap();
    std::fs::write(
        cell.join("arm.urdf"),
        r#"<?xml version="1.0"?><robot name="arm"><link name="base"><collision><geometry><mesh filename="package://my_robot/meshes/base.stl"/></geometry></collision></link><link name="l1"/><joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="0"/></joint></robot>"#,
    )
    .unwrap();
    std::fs::write(
        cell.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nurdf = \"arm.urdf\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap();
    std::fs::write(cell.join("r1.wsl"), "proc main() {}\n").unwrap();
    let run = |ros: Option<&std::path::Path>| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_vworks"));
        c.args(["run", cell.join("cell.toml").to_str().unwrap()])
            .env("NO_COLOR", "1")
            .env_remove("ROS_PACKAGE_PATH")
            .env_remove("AMENT_PREFIX_PATH");
        if let Some(p) = ros {
            c.env("ROS_PACKAGE_PATH", p);
        }
        c.output().unwrap()
    };
    let without = run(None);
    assert_eq!(without.status.code(), Some(1), "{}", text(&without.stdout));
    assert!(text(&without.stderr).contains("ROS_PACKAGE_PATH"));
    let with = run(Some(&share));
    assert_eq!(with.status.code(), Some(0), "{}", text(&with.stderr));
}

/// `log events` prints the contract's trace lines (integer ns), byte-identical to `run
/// --trace-ns`; with `--seconds`, byte-identical to `run --trace`.
#[test]
fn log_events_match_the_run_trace_in_both_styles() {
    let d = temp_dir("log-seconds");
    let log = d.join("crash.mcap");
    let log = log.to_str().unwrap();
    let run_ns = vworks(&["run", &workcell("crash"), "--trace-ns", "--log", log]);
    let events = vworks(&["log", "events", log]);
    assert_eq!(text(&events.stdout), text(&run_ns.stdout));
    assert!(text(&events.stdout).starts_with("0 left motion_start move_j duration="));
    let run_s = vworks(&["run", &workcell("crash"), "--trace"]);
    let seconds = vworks(&["log", "events", "--seconds", log]);
    assert_eq!(text(&seconds.stdout), text(&run_s.stdout));
    assert!(text(&seconds.stdout).starts_with("0 s left motion_start move_j duration="));
    // `log info` counts in words: the crash's one near-miss warning is one /log message.
    let info = text(&vworks(&["log", "info", log]).stdout);
    assert!(info.contains("  /log              1 message\n"), "{info}");
    assert!(info.contains("  /events           4 messages\n"), "{info}");
    let _ = std::fs::remove_dir_all(&d);
}

/// `vworks check mycell/cell.toml` read the workcell as a WSL program, and `vworks check
/// mycell/` said "Is a directory": a workcell (or its folder) is checked as `run` loads
/// it, and more, without running it. Every example checks clean: what check reports, a
/// run would too.
#[test]
fn check_takes_a_workcell_or_its_folder() {
    let examples = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../workcells");
    let mut names: Vec<String> = std::fs::read_dir(&examples)
        .unwrap()
        .filter_map(|e| {
            let e = e.unwrap();
            e.path()
                .join("cell.toml")
                .is_file()
                .then(|| e.file_name().to_string_lossy().into_owned())
        })
        .collect();
    names.sort();
    assert!(names.len() >= 8, "{names:?}");
    for name in &names {
        let folder = examples.join(name);
        let out = vworks(&["check", folder.to_str().unwrap()]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{name}: {err}");
        assert!(err.contains(" 0 errors, 0 warnings"), "{name}: {err}");
    }
    let out = vworks(&["check", &workcell("handoff")]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(
        text(&out.stderr),
        "checked cell handoff: 2 programs, 0 errors, 0 warnings\n"
    );
    // The run agrees that the cell is sound, and check ran nothing: no output but the line.
    assert!(text(&out.stdout).is_empty());
}

#[test]
fn check_json_lists_each_problem_with_its_place() {
    let d = temp_dir("check-json");
    std::fs::write(
        d.join("cell.toml"),
        "name = \"c\"\n[[robot]]\nname = \"r1\"\nmodel = \"kr6r900\"\nprogram = \"r1.wsl\"\nhome = [\"0deg\", \"-90deg\", \"90deg\", \"0deg\", \"30deg\", \"0deg\"]\n",
    )
    .unwrap();
    std::fs::write(
        d.join("r1.wsl"),
        "proc main() {\n    move_j joints(0deg, -90deg, 90deg, 0deg, 130deg, 0deg);\n    move_l pose(3000mm, 0mm, 500mm, 180deg, 0deg, 0deg);\n}\n",
    )
    .unwrap();
    let out = vworks(&["check", d.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", text(&out.stdout)));
    assert_eq!(v["cell"], "c");
    assert_eq!(v["programs"], 1);
    let errors = v["errors"].as_array().unwrap();
    let places: Vec<(String, u64, String)> = errors
        .iter()
        .map(|e| {
            (
                e["kind"].as_str().unwrap().to_string(),
                e["line"].as_u64().unwrap(),
                e["file"]
                    .as_str()
                    .unwrap()
                    .rsplit('/')
                    .next()
                    .unwrap()
                    .to_string(),
            )
        })
        .collect();
    assert_eq!(
        places,
        [
            ("limits".to_string(), 2, "r1.wsl".to_string()),
            ("reach".to_string(), 3, "r1.wsl".to_string())
        ]
    );
    assert!(
        errors[0]["message"]
            .as_str()
            .unwrap()
            .contains("axis 5 `joint_a5` would go to 130.0deg"),
        "{v}"
    );
    assert_eq!(v["warnings"], serde_json::json!([]));
    // The human form says the same on stderr, and nothing is printed on stdout.
    let out = vworks(&["check", d.join("cell.toml").to_str().unwrap()]);
    assert!(text(&out.stdout).is_empty());
    assert!(
        text(&out.stderr).ends_with("checked cell c: 1 program, 2 errors, 0 warnings\n"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn run_takes_a_workcells_folder() {
    let folder = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../workcells/handoff");
    let out = vworks(&["run", folder.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("\ncell handoff: completed at 46.491 s\n"),
        "{}",
        text(&out.stdout)
    );
    // With --json, a program given instead is still one JSON object, its message in it.
    let out = vworks(&[
        "run",
        &folder.join("r1.wsl").display().to_string(),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["outcome"], "error");
    assert!(
        v["errors"][0]["message"]
            .as_str()
            .unwrap()
            .contains("takes a workcell"),
        "{v}"
    );
}

/// `vworks new --model M` for every built-in arm: the cell checks clean and runs to the
/// end without a collision (its home, its targets and its table suit the model).
#[test]
fn new_makes_a_cell_that_runs_for_every_arm() {
    let d = temp_dir("new-arms");
    for model in ["irb120", "kr6r900", "lrmate200id", "ur5"] {
        let cell = d.join(model);
        let out = vworks(&["new", cell.to_str().unwrap(), "--model", model]);
        assert_eq!(out.status.code(), Some(0), "{model}: {}", text(&out.stderr));
        assert!(
            text(&out.stderr).contains(&format!("one {model} and a table")),
            "{}",
            text(&out.stderr)
        );
        let toml = std::fs::read_to_string(cell.join("cell.toml")).unwrap();
        assert!(toml.contains(&format!("model = \"{model}\"")), "{toml}");
        let out = vworks(&["check", cell.to_str().unwrap()]);
        assert_eq!(
            text(&out.stderr),
            format!("checked cell {model}: 1 program, 0 errors, 0 warnings\n")
        );
        let out = vworks(&["run", cell.to_str().unwrap(), "--json"]);
        assert_eq!(out.status.code(), Some(0), "{model}: {}", text(&out.stdout));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["outcome"], "completed", "{model}: {v}");
        assert_eq!(v["collisions"], serde_json::json!([]), "{model}");
        assert_eq!(v["errors"], serde_json::json!([]), "{model}");
        assert_eq!(v["warnings"], serde_json::json!([]), "{model}");
        // Six motions (three rounds of two), every one made.
        assert_eq!(v["robots"][0]["motions"], 6, "{model}: {v}");
    }
}

/// The report's line counted `1 robots`.
#[test]
fn the_report_line_counts_in_words() {
    let d = temp_dir("report-plural");
    let cell = d.join("one");
    assert_eq!(
        vworks(&["new", cell.to_str().unwrap()]).status.code(),
        Some(0)
    );
    let log = d.join("run.mcap");
    let out = vworks(&[
        "run",
        cell.to_str().unwrap(),
        "--log",
        log.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let out = vworks(&["report", log.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let err = text(&out.stderr);
    assert!(err.contains("(1 robot, "), "{err}");
    assert!(err.contains(" events, 0 collisions)"), "{err}");
}

/// `vworks new` writes the name as a TOML string: a name with a quote or a backslash
/// makes a cell that loads and runs; `--model` takes any case.
#[test]
fn new_escapes_the_name_and_takes_the_model_in_any_case() {
    let d = temp_dir("new-names");
    for (name, model) in [("a\"b", "irb120"), ("x\\y", "IRB120"), ("k", "Kr6R900")] {
        let cell = d.join(name);
        let out = vworks(&["new", cell.to_str().unwrap(), "--model", model]);
        assert_eq!(out.status.code(), Some(0), "{name}: {}", text(&out.stderr));
        let toml = std::fs::read_to_string(cell.join("cell.toml")).unwrap();
        assert!(
            toml.contains(&format!("model = \"{}\"", model.to_lowercase())),
            "{toml}"
        );
        let out = vworks(&["run", cell.to_str().unwrap(), "--json"]);
        assert_eq!(out.status.code(), Some(0), "{name}: {}", text(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["outcome"], "completed", "{name}: {v}");
        assert_eq!(v["cell"], name, "{v}");
    }
    // A model it does not know: the nearest arm suggested.
    let out = vworks(&["new", d.join("n").to_str().unwrap(), "--model", "kr6"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("`kr6` is not a built-in model (did you mean kr6r900?)"),
        "{}",
        text(&out.stderr)
    );
}

/// `check --json` names the robot of a workcell problem in a robot's table and of a
/// diagnostic in a robot's program; one cell prints an object, several an array.
#[test]
fn check_json_names_the_robot_and_takes_several_cells() {
    let d = temp_dir("check-json-robot");
    std::fs::write(
        d.join("cell.toml"),
        "name = \"c\"\n[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\nhome = [\"0deg\", \"-130deg\", \"0deg\", \"0deg\", \"30deg\", \"0deg\"]\n",
    )
    .unwrap();
    std::fs::write(d.join("r1.wsl"), "proc main() {\n    delay 2;\n}\n").unwrap();
    let out = vworks(&["check", d.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let errors = v["errors"].as_array().unwrap();
    let kinds: Vec<(&str, &str)> = errors
        .iter()
        .map(|e| {
            (
                e["kind"].as_str().unwrap(),
                e["robot"].as_str().unwrap_or("null"),
            )
        })
        .collect();
    assert_eq!(kinds, [("E0021", "r1"), ("workcell", "r1")], "{v}");
    let both = vworks(&[
        "check",
        d.to_str().unwrap(),
        d.join("cell.toml").to_str().unwrap(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&both.stdout).unwrap();
    assert_eq!(v.as_array().map(Vec::len), Some(2), "{v}");
}
