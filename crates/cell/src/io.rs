//! The workcell's I/O wiring (`[[io]]`): which robot's output drives which robot's inputs.
//!
//! Each `[[io]]` table is one wire, named by its signal (cell-wide, case-insensitive):
//! an output (`kind = "do"` or `"go"`) that a robot's program writes, with the inputs of
//! other robots it drives (`inputs = [{ robot = "r2", name = "diPartReady" }]`), or an
//! input no robot drives (`kind = "di"`/`"gi"`, constant at its `value`). A wire is one of
//! the cell's globals (an int, named by the wire in lower case), so a WSL program reads
//! it as `global dopartready = 0;`. RAPID programs are compiled with their robot's
//! signals (`vworks_wslc::rapid::compile_with_io`); a signal a program names that its
//! robot does not have is error E0302 at the program's line.

use vworks_wslc::rapid::{IoSignal, SignalKind};

use crate::context::Ctx;
use crate::error::CellError;
use crate::file::IoFile;

/// Each robot's signals (in robot order), from the `[[io]]` tables; `None` when the cell
/// has none (then a RAPID program's signals are globals of their own names).
pub(crate) fn signals(
    cx: &Ctx<'_>,
    io: &[IoFile],
    robots: &[&str],
) -> Result<Option<Vec<Vec<IoSignal>>>, CellError> {
    if io.is_empty() {
        return Ok(None);
    }
    let mut out: Vec<Vec<IoSignal>> = vec![Vec::new(); robots.len()];
    let mut wires: Vec<String> = Vec::new();
    let robot_index = |key: &str, name: &str| -> Result<usize, CellError> {
        robots.iter().position(|r| *r == name).ok_or_else(|| {
            cx.bad(
                key,
                format!(
                    "there is no robot `{name}`; the robots are {}",
                    robots.join(", ")
                ),
            )
        })
    };
    for (i, w) in io.iter().enumerate() {
        let key = format!("io[{i}] `{}`", w.name);
        let Some(kind) = SignalKind::from_name(&w.kind) else {
            return Err(cx.bad(
                &format!("{key}.kind"),
                format!(
                    "`{}` is not a signal kind; write \"do\" or \"go\" (an output that drives inputs), \"di\" or \"gi\" (an input no robot drives)",
                    w.kind
                ),
            ));
        };
        let global = w.name.to_ascii_lowercase();
        if global.is_empty()
            || !global
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_')
        {
            return Err(cx.bad(
                &format!("{key}.name"),
                "a signal's name is letters, digits and `_`, as in RAPID",
            ));
        }
        if wires.contains(&global) {
            return Err(cx.bad(
                &format!("{key}.name"),
                format!(
                    "the signal `{}` is declared twice (names are case-insensitive)",
                    w.name
                ),
            ));
        }
        wires.push(global.clone());
        let init = w.value.unwrap_or(0);
        let digital = matches!(kind, SignalKind::Di | SignalKind::Do);
        if init < 0 || (digital && init > 1) {
            return Err(cx.bad(
                &format!("{key}.value"),
                format!(
                    "{init} is not a value of a {} signal; use {}",
                    kind.name(),
                    if digital {
                        "0 or 1"
                    } else {
                        "a whole number from 0"
                    }
                ),
            ));
        }
        if !kind.is_output() && !w.inputs.is_empty() {
            return Err(cx.bad(
                &format!("{key}.inputs"),
                "an input drives nothing; make the wire an output (\"do\" or \"go\") of the robot that writes it",
            ));
        }
        let owner = robot_index(&format!("{key}.robot"), &w.robot)?;
        let mut add = |r: usize, name: &str, kind: SignalKind, k: &str| -> Result<(), CellError> {
            if out[r].iter().any(|s| s.name.eq_ignore_ascii_case(name)) {
                return Err(cx.bad(
                    k,
                    format!("robot `{}` has two signals named `{name}`", robots[r]),
                ));
            }
            out[r].push(IoSignal {
                name: name.to_string(),
                kind,
                global: global.clone(),
                init,
            });
            Ok(())
        };
        add(owner, &w.name, kind, &format!("{key}.name"))?;
        let input_kind = if digital {
            SignalKind::Di
        } else {
            SignalKind::Gi
        };
        for (j, inp) in w.inputs.iter().enumerate() {
            let k = format!("{key}.inputs[{j}]");
            let r = robot_index(&format!("{k}.robot"), &inp.robot)?;
            add(r, &inp.name, input_kind, &format!("{k}.name"))?;
        }
    }
    Ok(Some(out))
}
