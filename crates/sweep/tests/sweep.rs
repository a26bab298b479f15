//! Sweeps: the file's variants, running them (the same table whatever the threads), and
//! each row equal to a plain run of the workcell written out with that variant's values.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use vworks_cell::{Disk, Loader, MemoryFiles, Override};
use vworks_log::result::Outcome;
use vworks_sweep::run::{RunOptions, run_one};
use vworks_sweep::table::{self, Value};
use vworks_sweep::{Combine, RowOutcome, Sweep, Table, run_variants};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn sweep_of(text: &str) -> Result<Sweep, String> {
    let mut files = MemoryFiles::default();
    files.insert("s/sweep.toml", text.as_bytes().to_vec());
    Sweep::read(Path::new("s/sweep.toml"), &files).map_err(|e| e.to_string())
}

#[test]
fn a_product_varies_the_last_variable_fastest_and_zip_pairs_them() {
    let s = sweep_of(
        "cell = \"cell.toml\"\n[[variable]]\npath = \"cycle\"\nvalues = [\"2ms\", \"4ms\"]\n[[variable]]\npath = [\"params.a\", \"params.b\"]\nrange = { from = 1, to = 3, steps = 3 }\n",
    )
    .unwrap();
    assert_eq!(s.cell, Path::new("s/cell.toml"));
    assert_eq!(s.combine, Combine::Product);
    let v = s.variants();
    assert_eq!(v.len(), 6);
    let show = |o: &[Override]| {
        o.iter()
            .map(|o| format!("{}={}", o.path, o.value))
            .collect::<Vec<_>>()
            .join(" ")
    };
    assert_eq!(show(&v[0]), "cycle=\"2ms\" params.a=1 params.b=1");
    assert_eq!(show(&v[1]), "cycle=\"2ms\" params.a=2 params.b=2");
    assert_eq!(show(&v[5]), "cycle=\"4ms\" params.a=3 params.b=3");
    let z = sweep_of(
        "cell = \"c.toml\"\ncombine = \"zip\"\n[[variable]]\npath = \"cycle\"\nvalues = [\"2ms\", \"4ms\"]\n[[variable]]\npath = \"clearance\"\nrange = { from = \"1mm\", to = \"3mm\", steps = 2 }\n",
    )
    .unwrap();
    let v = z.variants();
    assert_eq!(v.len(), 2);
    assert_eq!(show(&v[1]), "cycle=\"4ms\" clearance=0.003");
}

#[test]
fn random_samples_depend_on_the_seed_only() {
    let text = |seed: u64| {
        format!(
            "cell = \"c.toml\"\nseed = {seed}\n[[variable]]\npath = \"clearance\"\nrandom = {{ from = \"1mm\", to = \"5mm\", count = 50 }}\n"
        )
    };
    let a = sweep_of(&text(7)).unwrap().variants();
    assert_eq!(a, sweep_of(&text(7)).unwrap().variants());
    assert_ne!(a, sweep_of(&text(8)).unwrap().variants());
    let xs: Vec<f64> = a.iter().map(|o| o[0].value.as_float().unwrap()).collect();
    assert!(xs.iter().all(|x| (0.001..0.005).contains(x)), "{xs:?}");
    // Spread over the interval, not stuck: both halves are hit.
    assert!(xs.iter().any(|x| *x < 0.003) && xs.iter().any(|x| *x > 0.003));
}

#[test]
fn wrong_sweep_files_say_what_to_write() {
    let cases = [
        ("cell = \"c.toml\"\n", "at least one [[variable]]"),
        (
            "cell = \"c.toml\"\n[[variable]]\npath = \"cycle\"\nvalues = [1]\nrange = { from = 1, to = 2, steps = 2 }\n",
            "exactly one of",
        ),
        (
            "cell = \"c.toml\"\ncombine = \"zip\"\n[[variable]]\npath = \"cycle\"\nvalues = [1, 2]\n[[variable]]\npath = \"clearance\"\nvalues = [1]\n",
            "as many values",
        ),
        (
            "cell = \"c.toml\"\ncombine = \"cross\"\n[[variable]]\npath = \"cycle\"\nvalues = [1]\n",
            "\"product\" or \"zip\"",
        ),
        (
            "cell = \"c.toml\"\n[[variable]]\npath = \"cycle\"\nrange = { from = \"1mm\", to = \"2s\", steps = 2 }\n",
            "same unit",
        ),
        (
            "cell = \"c.toml\"\n[[variable]]\npath = 3\nvalues = [1]\n",
            "a path is a string",
        ),
        ("cell = \"c.toml\"\nvariabel = 1\n", "docs/sweep.md"),
    ];
    for (text, want) in cases {
        let e = sweep_of(text).unwrap_err();
        assert!(e.contains(want), "{text}: {e}");
        assert!(e.starts_with("s/sweep.toml: "), "{e}");
    }
}

#[test]
fn the_table_is_the_same_whatever_the_threads() {
    let sweep = Sweep::read(&root().join("workcells/handoff/sweep.toml"), &Disk).unwrap();
    let loader = Loader::new(&sweep.cell, &Disk).unwrap();
    // Every 4th variant of the 121 (a product of 11 × 11), plus one that cannot load.
    let mut variants: Vec<Vec<Override>> = sweep.variants().into_iter().step_by(4).collect();
    variants.push(vec![Override::new("robot.r2.base.xyz.0", "tall")]);
    let robots = vec!["r1".to_string(), "r2".to_string()];
    let names = vec![
        "robot.r2.base.xyz.0".to_string(),
        "robot.r2.base.xyz.1".to_string(),
    ];
    let mut tables = Vec::new();
    let mut first_rows = Vec::new();
    for jobs in [1, 2, 3] {
        let options = RunOptions {
            jobs,
            ..RunOptions::default()
        };
        let rows = run_variants(&loader, &variants, &options, &|_| {}, None);
        assert_eq!(rows.len(), variants.len());
        assert!(rows.iter().enumerate().all(|(i, r)| r.index == i));
        tables.push(Table::new(&names, &robots, &rows).csv());
        if first_rows.is_empty() {
            first_rows = rows;
        }
    }
    assert_eq!(tables[0], tables[1]);
    assert_eq!(tables[0], tables[2]);
    let last = first_rows.last().unwrap();
    assert_eq!(last.outcome, RowOutcome::Invalid);
    assert!(last.error.contains("tall"), "{}", last.error);
    // Outcomes of all kinds: completed, collision, error (unreachable).
    for o in [Outcome::Completed, Outcome::Collision, Outcome::Error] {
        assert!(
            first_rows.iter().any(|r| r.outcome == RowOutcome::Run(o)),
            "{o:?}"
        );
    }
}

#[test]
fn a_row_is_the_run_of_the_workcell_written_with_its_values() {
    // The variant r2 at x 500 mm, y 600 mm, against the cell file edited by hand to say so.
    let loader = Loader::new(&root().join("workcells/handoff/cell.toml"), &Disk).unwrap();
    let variant = [
        Override::new("robot.r2.base.xyz.0", "500mm"),
        Override::new("robot.r2.params.base_x", "500mm"),
        Override::new("robot.r2.base.xyz.1", "600mm"),
        Override::new("robot.r2.params.base_y", "600mm"),
    ];
    let row = run_one(&loader, 0, &variant, &RunOptions::default());
    let dir = std::env::temp_dir().join(format!("vworks-sweep-edit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["r1.wsl", "r2.wsl"] {
        std::fs::copy(root().join("workcells/handoff").join(f), dir.join(f)).unwrap();
    }
    let text = std::fs::read_to_string(root().join("workcells/handoff/cell.toml")).unwrap();
    let edited = text.replacen(
        "base = { xyz = [\"600mm\", \"600mm\", \"0mm\"]",
        "params = { base_x = \"500mm\", base_y = \"600mm\" }\nbase = { xyz = [\"500mm\", \"600mm\", \"0mm\"]",
        1,
    );
    assert_ne!(edited, text);
    std::fs::write(dir.join("cell.toml"), edited).unwrap();
    let cell = Arc::new(vworks_cell::load(&dir.join("cell.toml")).unwrap());
    let plain = vworks_se::Simulation::new(cell).run(None);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(row.outcome, RowOutcome::Run(plain.outcome));
    assert_eq!(row.end_time, plain.end_time_ns as f64 / 1e9);
    assert_eq!(row.end_time, 46.022072698);
    assert_eq!(
        row.cycle_times,
        plain
            .robots
            .iter()
            .map(|r| (r.name.clone(), Some(r.end_time_ns as f64 / 1e9)))
            .collect::<Vec<_>>()
    );
}

#[test]
fn the_best_are_completed_without_collision_smallest_first() {
    let sweep = Sweep::read(&root().join("workcells/handoff/sweep.toml"), &Disk).unwrap();
    let loader = Loader::new(&sweep.cell, &Disk).unwrap();
    let variants: Vec<Vec<Override>> = sweep.variants().into_iter().step_by(3).collect();
    let rows = run_variants(&loader, &variants, &RunOptions::default(), &|_| {}, None);
    let names = vec!["robot.r2.base.xyz.0".to_string()];
    let table = Table::new(&names, &["r1".into(), "r2".into()], &rows);
    let best = table.best("end_time", 3).unwrap();
    assert_eq!(best.len(), 3);
    let k = table.column("end_time").unwrap();
    let t = |i: usize| table.rows[i][k].number().unwrap();
    assert!(t(best[0]) <= t(best[1]) && t(best[1]) <= t(best[2]));
    for (i, r) in rows.iter().enumerate() {
        if r.feasible() {
            assert!(t(i) >= t(best[0]));
        }
    }
    assert!(best.iter().all(
        |i| rows[*i].outcome == RowOutcome::Run(Outcome::Completed) && rows[*i].collisions == 0
    ));
    let e = table.best("speed", 3).unwrap_err();
    assert!(e.contains("end_time") && e.contains("cycle_time.r1"), "{e}");
    // The page charts the objective over the one variable named (a scatter).
    let page = vworks_sweep::html::page("t", &table, &names, "end_time", &best);
    assert!(page.contains("<svg id=\"chart\"") && page.contains("class=\"feasible\""));
}

/// `steps = 4294967296` aborted allocating 137 GB and `count = 2^64-1` panicked: the
/// counts are checked before anything is made, and the error names the key.
#[test]
fn absurd_sizes_are_errors_naming_the_key() {
    for (line, key) in [
        (
            "range = { from = \"1ms\", to = \"8ms\", steps = 4294967296 }",
            "variable[0] `cycle`.range.steps",
        ),
        (
            "random = { from = \"1ms\", to = \"8ms\", count = 18446744073709551615 }",
            "variable[0] `cycle`.random.count",
        ),
    ] {
        let text = format!("cell = \"c.toml\"\n[[variable]]\npath = \"cycle\"\n{line}\n");
        let e = sweep_of(&text).unwrap_err();
        assert!(
            e.starts_with(&format!("s/sweep.toml: {key}: ")) && e.contains("give fewer"),
            "{e}"
        );
    }
    // Each variable within the limit, their product over it: every size named.
    let text = "cell = \"c.toml\"\n[[variable]]\npath = \"cycle\"\nrange = { from = 1, to = 9, steps = 5000000 }\n[[variable]]\npath = \"clearance\"\nrange = { from = 1, to = 9, steps = 3 }\n";
    let e = sweep_of(text).unwrap_err();
    assert!(
        e.contains("5000000 × 3 values make more than 10000000 variants"),
        "{e}"
    );
    // Within it, a range of millions of values is made when asked for, not before.
    let text = "cell = \"c.toml\"\n[[variable]]\npath = \"cycle\"\nrange = { from = 0, to = 9999999, steps = 10000000 }\n";
    let s = sweep_of(text).unwrap();
    assert_eq!(s.count(), 10_000_000);
    assert_eq!(s.variant(1234567)[0].value, toml::Value::Integer(1234567));
}

/// The k-th random sample is made directly; it is the k-th of the generator run in turn.
#[test]
fn random_samples_are_splitmix64_in_turn() {
    let text = "cell = \"c.toml\"\nseed = 7\n[[variable]]\npath = \"cycle\"\nvalues = [1]\n[[variable]]\npath = \"clearance\"\nrandom = { from = 0.0, to = 1.0, count = 50 }\n";
    let s = sweep_of(text).unwrap();
    let mut state: u64 = 7 ^ 0x9E37_79B9_7F4A_7C15; // the seed ^ the variable's index × golden
    for k in 0..50 {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let want = (z >> 11) as f64 / (1u64 << 53) as f64;
        assert_eq!(
            s.variant(k)[1].value,
            toml::Value::Float(want),
            "sample {k}"
        );
    }
}

/// `minimize = "cycle_time.r3"` was found wrong after every variant ran: now before.
#[test]
fn the_objective_is_checked_before_running() {
    let sweep = Sweep::read(&root().join("workcells/handoff/sweep.toml"), &Disk).unwrap();
    let robots = vec!["r1".to_string(), "r2".to_string()];
    for ok in [
        "end_time",
        "cycle_time.r2",
        "robot.r2.base.xyz.0",
        "collisions",
    ] {
        assert_eq!(
            sweep.check_objective(ok, &robots),
            Ok(ok.to_string()),
            "{ok}"
        );
    }
    // Named as the table file's header names it, with its unit, too.
    for (header, key) in [
        ("end_time [s]", "end_time"),
        ("cycle_time.r2 [s]", "cycle_time.r2"),
        ("robot.r2.base.xyz.0 [mm]", "robot.r2.base.xyz.0"),
    ] {
        assert_eq!(
            sweep.check_objective(header, &robots),
            Ok(key.to_string()),
            "{header}"
        );
    }
    assert!(sweep.check_objective("end_time [ms]", &robots).is_err());
    let e = sweep.check_objective("cycle_time.r3", &robots).unwrap_err();
    assert!(
        e.starts_with("`cycle_time.r3` is not a numeric column of the table; choose one of variant, robot.r2.base.xyz.0, robot.r2.base.xyz.1, end_time, cycle_time.r1, cycle_time.r2, collisions, min_clearance"),
        "{e}"
    );
}

/// A cell in a fresh folder whose r1 runs `body` (its `main`).
fn cell_running(name: &str, body: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vworks-sweep-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        "[[robot]]\nname = \"r1\"\nmodel = \"irb120\"\nprogram = \"r1.wsl\"\n",
    )
    .unwrap();
    std::fs::write(dir.join("r1.wsl"), format!("proc main() {{\n{body}\n}}\n")).unwrap();
    dir
}

/// A variant that never ends blocked the sweep: the wall-time limit makes it a
/// `timeout` row, and the variants after it run.
#[test]
fn an_endless_variant_is_stopped_at_its_timeout() {
    let dir = cell_running("endless", "    while true {\n        delay 1s;\n    }");
    let loader = Loader::new(&dir.join("cell.toml"), &Disk).unwrap();
    let variants = vec![
        vec![Override::new("cycle", "8ms")],
        vec![Override::new("cycle", "not a time")],
    ];
    let options = RunOptions {
        jobs: 1,
        variant_timeout: Some(std::time::Duration::from_millis(300)),
        ..RunOptions::default()
    };
    let rows = run_variants(&loader, &variants, &options, &|_| {}, None);
    let _ = std::fs::remove_dir_all(&dir);
    let outcomes: Vec<RowOutcome> = rows.iter().map(|r| r.outcome).collect();
    assert_eq!(outcomes, [RowOutcome::Timeout, RowOutcome::Invalid]);
    assert!(
        rows[0].error.contains("variant timeout of 0.3 s"),
        "{}",
        rows[0].error
    );
    assert!(rows[0].end_time > 0.0);
}

/// A log that cannot be written (a full disk: /dev/full) made a `completed` row with an
/// empty log: now the row is an error saying why.
#[cfg(target_os = "linux")]
#[test]
fn a_log_that_cannot_be_written_is_the_variants_error() {
    let dir = cell_running("full", "    delay 1s;");
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    std::os::unix::fs::symlink("/dev/full", logs.join("variant-00000.mcap")).unwrap();
    let loader = Loader::new(&dir.join("cell.toml"), &Disk).unwrap();
    let variants = vec![
        vec![Override::new("cycle", "8ms")],
        vec![Override::new("cycle", "4ms")],
    ];
    let options = RunOptions {
        keep_logs: Some(logs.clone()),
        ..RunOptions::default()
    };
    let rows = run_variants(&loader, &variants, &options, &|_| {}, None);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(rows[0].outcome, RowOutcome::Run(Outcome::Error));
    assert!(rows[0].log_failed);
    assert!(
        rows[0].error.contains("No space left on device"),
        "{}",
        rows[0].error
    );
    assert_eq!(rows[1].outcome, RowOutcome::Run(Outcome::Completed));
    assert!(!rows[1].log_failed);
}

/// `robot.r2.base.xyz.0 = 0.5` for 500 mm, `5deg` as 0.0873: a variable written with a
/// unit is shown in it, its header says it, and plain numbers stay as they are.
#[test]
fn the_table_file_shows_each_variable_in_the_unit_it_was_written_in() {
    let s = sweep_of(
        "cell = \"c.toml\"\n\
         [[variable]]\npath = \"robot.r2.base.xyz.0\"\nrange = { from = \"250mm\", to = \"750mm\", steps = 11 }\n\
         [[variable]]\npath = \"robot.r2.base.rpy.2\"\nvalues = [\"5deg\", \"-12.5deg\", 0.5]\n\
         [[variable]]\npath = \"params.speed\"\nvalues = [\"200mm/s\", 0.3]\n\
         [[variable]]\npath = \"cycle\"\nvalues = [0.004, 0.008]\n\
         [[variable]]\npath = \"clearance\"\nvalues = [\"5mm\", \"4ms\"]\n",
    )
    .unwrap();
    let units: Vec<Option<String>> = s
        .variables
        .iter()
        .map(|v| v.unit.as_ref().map(|u| u.name.clone()))
        .collect();
    // Plain numbers: no unit; values of two dimensions: the first's (the other as written).
    assert_eq!(
        units,
        [Some("mm"), Some("deg"), Some("mm/s"), None, Some("mm")].map(|u| u.map(String::from))
    );
    let robots = vec!["r1".to_string()];
    assert_eq!(
        table::headers(&s.names(), &s.units(), &robots),
        [
            "variant",
            "robot.r2.base.xyz.0 [mm]",
            "robot.r2.base.rpy.2 [deg]",
            "params.speed [mm/s]",
            "cycle",
            "clearance [mm]",
            "outcome",
            "end_time [s]",
            "cycle_time.r1 [s]",
            "collisions",
            "min_clearance [m]",
            "error",
        ]
    );
    let shown = |k: usize, v: usize| {
        let value = s.variables[k].values.get(v);
        table::in_unit(&value, s.variables[k].unit.as_ref())
    };
    // A range's values are made in SI (0.25 + 0.05 k m): shown in mm as the ends were.
    let range: Vec<Value> = (0..11).map(|v| shown(0, v)).collect();
    let want: Vec<Value> = (0..11)
        .map(|k| Value::Num(250.0 + 50.0 * k as f64))
        .collect();
    assert_eq!(range, want);
    // As written; a plain number is SI, shown converted: 0.5 rad is 180/π · 0.5 deg.
    assert_eq!(shown(1, 0), Value::Num(5.0));
    assert_eq!(shown(1, 1), Value::Num(-12.5));
    let deg = shown(1, 2).number().unwrap();
    assert!((deg - 0.5_f64.to_degrees()).abs() < 1e-9, "{deg}");
    assert_eq!(shown(2, 0), Value::Num(200.0));
    assert_eq!(shown(2, 1), Value::Num(300.0));
    assert_eq!(shown(3, 1), Value::Num(0.008));
    assert_eq!(shown(4, 0), Value::Num(5.0));
    assert_eq!(shown(4, 1), Value::Text("4ms".into()));
}

/// `["fine", "10mm", "20mm"]` showed `fine`, 0.01, 0.02 (no unit), and one value of an
/// unknown unit (`"0.5cm"`) or of another dimension turned the whole column into SI
/// numbers: a value that is not a quantity of the column's unit is shown as written, and
/// the others keep the unit of most of them.
#[test]
fn a_value_that_is_not_a_quantity_does_not_change_the_others() {
    let s = sweep_of(
        "cell = \"c.toml\"\n\
         [[variable]]\npath = \"robot.r1.default_zone\"\nvalues = [\"fine\", \"10mm\", \"20mm\", 0.03]\n\
         [[variable]]\npath = \"robot.r2.base.xyz.0\"\nvalues = [\"500mm\", \"0.5cm\", \"0.6m\", true]\n\
         [[variable]]\npath = \"robot.r2.base.xyz.1\"\nvalues = [\"5deg\", \"500mm\", \"600mm\"]\n\
         [[variable]]\npath = \"params.mode\"\nvalues = [\"fast\", \"slow\"]\n",
    )
    .unwrap();
    let shown = |k: usize| -> Vec<Value> {
        s.variables[k]
            .values
            .to_vec()
            .iter()
            .map(|v| table::in_unit(v, s.variables[k].unit.as_ref()))
            .collect()
    };
    let text = |t: &str| Value::Text(t.into());
    assert_eq!(
        shown(0),
        [
            text("fine"),
            Value::Num(10.0),
            Value::Num(20.0),
            Value::Num(30.0)
        ]
    );
    assert_eq!(
        shown(1),
        [
            Value::Num(500.0),
            text("0.5cm"),
            Value::Num(600.0),
            text("true")
        ]
    );
    // Most are lengths: the column is in mm, whatever came first.
    assert_eq!(
        shown(2),
        [text("5deg"), Value::Num(500.0), Value::Num(600.0)]
    );
    assert_eq!(shown(3), [text("fast"), text("slow")]);
    let robots = vec!["r1".to_string()];
    assert_eq!(
        table::headers(&s.names(), &s.units(), &robots)[1..5],
        [
            "robot.r1.default_zone [mm]",
            "robot.r2.base.xyz.0 [mm]",
            "robot.r2.base.xyz.1 [mm]",
            "params.mode",
        ]
    );
    // A column with a word is no objective: not every value is a number.
    let err = s
        .check_objective("robot.r1.default_zone", &robots)
        .unwrap_err();
    assert!(err.contains("choose one of variant, end_time"), "{err}");
}
