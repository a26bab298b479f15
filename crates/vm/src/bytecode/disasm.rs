//! A readable listing of a module: its tables, then every procedure's instructions with
//! operands resolved to names and, when the source is at hand, the source line beside the
//! first instruction that comes from it.

use std::fmt::Write;

use super::instr::Instr;
use super::*;

/// Lists the module. With `sources` (the text of each of the module's files, in order),
/// each new source line is printed beside its first instruction. Positions are
/// `line:col`, or `file:line:col` in a module of several files.
pub fn disassemble(m: &Module, sources: &[&str]) -> String {
    let lines: Vec<Vec<&str>> = sources.iter().map(|s| s.lines().collect()).collect();
    let at = |p: SrcPos| -> String {
        if m.files.len() > 1 {
            format!("{}:{p}", m.file_name_of(p))
        } else {
            p.to_string()
        }
    };
    let mut o = String::new();
    let _ = writeln!(o, "; module {} (WSLB v{})", m.source_path(), FORMAT_VERSION);
    if !m.globals.is_empty() {
        let _ = writeln!(o, "\n; globals");
        for (i, g) in m.globals.iter().enumerate() {
            let _ = writeln!(
                o,
                "g{i:<3} global {}: {} = {}  ; {}",
                m.str(g.name),
                g.ty,
                g.init.display(g.ty),
                at(g.pos)
            );
        }
    }
    if !m.vars.is_empty() {
        let _ = writeln!(o, "\n; module variables ({} slots)", m.var_slots);
        for v in &m.vars {
            let _ = writeln!(
                o,
                "v{:<3} {} {}: {} = {}  ; {}",
                v.slot,
                if v.param { "param" } else { "var" },
                m.str(v.name),
                v.ty,
                v.init.display(v.ty),
                at(v.pos)
            );
        }
    }
    if !m.consts.is_empty() {
        let _ = writeln!(o, "\n; constants");
        for (i, c) in m.consts.iter().enumerate() {
            let name = c
                .name
                .map_or("(pool)".to_string(), |n| m.str(n).to_string());
            let _ = writeln!(o, "k{i:<3} {name}: {} = {}", c.ty, c.value.display(c.ty));
        }
    }
    if !m.conds.is_empty() {
        let _ = writeln!(o, "\n; conditions");
        for (i, c) in m.conds.iter().enumerate() {
            let globals: Vec<&str> = c.globals.iter().map(|g| global_name(m, *g)).collect();
            let _ = writeln!(
                o,
                "c{i:<3} {}{} reads [{}]  ; {}",
                proc_name(m, c.func),
                captures(&c.captures),
                globals.join(", "),
                at(c.pos)
            );
        }
    }
    if !m.handlers.is_empty() {
        let _ = writeln!(o, "\n; handlers");
        for (i, h) in m.handlers.iter().enumerate() {
            let trigger = match h.trigger {
                Trigger::EveryCycles => "every N cycles".to_string(),
                Trigger::Every => "every T".to_string(),
                Trigger::After => "after T".to_string(),
                Trigger::Condition(c) => format!("on c{c}"),
            };
            let _ = writeln!(
                o,
                "h{i:<3} {trigger} do {} via {}{}  ; {}",
                proc_name(m, h.target),
                proc_name(m, h.action),
                captures(&h.captures),
                at(h.pos)
            );
        }
    }
    if !m.remotes.is_empty() {
        let _ = writeln!(o, "\n; remote sites");
        for (i, r) in m.remotes.iter().enumerate() {
            let args: Vec<String> = r.args.iter().map(|t| t.name()).collect();
            let _ = writeln!(
                o,
                "r{i:<3} {}.{}({})  ; {}",
                m.str(r.robot),
                m.str(r.proc),
                args.join(", "),
                at(r.pos)
            );
        }
    }
    if !m.signals_sent.is_empty() || !m.signals_awaited.is_empty() {
        let _ = writeln!(o, "\n; signals");
        for (i, x) in m.signals_sent.iter().enumerate() {
            let _ = writeln!(
                o,
                "s{i:<3} sends {}.{}  ; {}",
                m.str(x.robot),
                m.str(x.name),
                at(x.pos)
            );
        }
        let awaited: Vec<&str> = m.signals_awaited.iter().map(|s| m.str(*s)).collect();
        if !awaited.is_empty() {
            let _ = writeln!(o, "     awaits {}", awaited.join(", "));
        }
    }
    if !m.syncs.is_empty() {
        let _ = writeln!(o, "\n; sync points");
        for (i, x) in m.syncs.iter().enumerate() {
            let tasks: Vec<&str> = x.tasks.iter().map(|t| m.str(*t)).collect();
            let _ = writeln!(
                o,
                "y{i:<3} {} with {}  ; {}",
                m.str(x.name),
                tasks.join(", "),
                at(x.pos)
            );
        }
    }
    if !m.parts.is_empty() {
        let _ = writeln!(o, "\n; part sites");
        for (i, x) in m.parts.iter().enumerate() {
            let _ = writeln!(o, "p{i:<3} {}  ; {}", m.str(x.part), at(x.pos));
        }
    }
    for (pi, p) in m.procs.iter().enumerate() {
        let params: Vec<String> = p
            .params
            .iter()
            .map(|a| format!("{}: {}", m.str(a.name), a.ty))
            .collect();
        let ret = p.ret.map_or(String::new(), |t| format!(" -> {t}"));
        let _ = writeln!(
            o,
            "\n{} {}({}){ret}  ; #{pi} at {}, frame {} slots, stack {}",
            p.kind.keyword(),
            m.str(p.name),
            params.join(", "),
            at(p.pos),
            p.frame_slots,
            p.max_stack
        );
        let mut last_line = (0, 0);
        for (i, ins) in p.code(m).iter().enumerate() {
            let pc = p.code_start + i as u32;
            let pos = m.pos_of(pc);
            let text = format!("{:>5}  {:<14}{}", i, ins.name(), operands(m, ins));
            let shown = at(pos);
            let mut row = format!("{text:<44}; {shown}");
            if pos.line > 0 && (pos.file, pos.line) != last_line {
                if let Some(src) = lines
                    .get(pos.file as usize)
                    .and_then(|l| l.get(pos.line.saturating_sub(1) as usize))
                {
                    let _ = write!(
                        row,
                        "{}| {}",
                        " ".repeat(8usize.saturating_sub(shown.len())),
                        src.trim()
                    );
                }
                last_line = (pos.file, pos.line);
            }
            let _ = writeln!(o, "{}", row.trim_end());
        }
    }
    o
}

fn proc_name(m: &Module, p: u32) -> &str {
    m.procs.get(p as usize).map_or("?", |p| m.str(p.name))
}

fn global_name(m: &Module, g: u32) -> &str {
    m.globals.get(g as usize).map_or("?", |g| m.str(g.name))
}

fn captures(c: &[Capture]) -> String {
    if c.is_empty() {
        return String::new();
    }
    let parts: Vec<String> = c
        .iter()
        .map(|c| format!("l{}/{}", c.slot, c.width))
        .collect();
    format!(" captures [{}]", parts.join(", "))
}

fn operands(m: &Module, ins: &Instr) -> String {
    match *ins {
        Instr::PushBool(b) => b.to_string(),
        Instr::PushInt(i) => i.to_string(),
        Instr::PushNum(x) => crate::types::fmt_num(x),
        Instr::PushConst(k) => {
            let c = m.consts.get(k as usize);
            let name = c
                .and_then(|c| c.name)
                .map_or(String::new(), |n| format!(" ({})", m.str(n)));
            format!("k{k}{name}")
        }
        Instr::Pop(n) | Instr::MakeJoints(n) => n.to_string(),
        Instr::PoseGet(f) => ["x", "y", "z", "rx", "ry", "rz"]
            .get(f as usize)
            .unwrap_or(&"?")
            .to_string(),
        Instr::LoadLocal(s) | Instr::StoreLocal(s) | Instr::StoreLocalJoint(s) => format!("l{s}"),
        Instr::LoadLocalN(s, n) | Instr::StoreLocalN(s, n) => format!("l{s} {n}"),
        Instr::LoadVar(s) | Instr::StoreVar(s) | Instr::StoreVarJoint(s) => {
            format!("v{s}{}", var_name(m, s))
        }
        Instr::LoadVarN(s, n) | Instr::StoreVarN(s, n) => format!("v{s} {n}{}", var_name(m, s)),
        Instr::LoadGlobal(g) | Instr::StoreGlobal(g) | Instr::PulseGlobal(g) => {
            format!("g{g} ({})", global_name(m, g))
        }
        Instr::CmpI(c) | Instr::CmpF(c) | Instr::CmpB(c) => c.symbol().to_string(),
        Instr::Jump(t) | Instr::JumpIfFalse(t) | Instr::JumpIfTrue(t) => format!("-> {t}"),
        Instr::Call(p) | Instr::Disable(p) => proc_name(m, p).to_string(),
        Instr::MoveJ(f) | Instr::MoveL(f) | Instr::MoveC(f) => {
            let mut parts = vec![if f.has(MoveFlags::TARGET_JOINTS) {
                "joints"
            } else {
                "pose"
            }];
            if matches!(ins, Instr::MoveC(_)) {
                parts.push(if f.has(MoveFlags::VIA_JOINTS) {
                    "via joints"
                } else {
                    "via pose"
                });
            }
            if f.has(MoveFlags::SPEED) {
                parts.push(if f.has(MoveFlags::TCP_SPEED) {
                    "tcp-speed"
                } else {
                    "speed"
                });
            }
            if f.has(MoveFlags::ACCEL) {
                parts.push("accel");
            }
            if f.has(MoveFlags::ORIENT) {
                parts.push("orient");
            }
            if f.has(MoveFlags::ZONE) {
                parts.push("zone");
            }
            if f.has(MoveFlags::ZONE | MoveFlags::ZONE_ORI) {
                parts.push("ori-zone");
            }
            if f.has(MoveFlags::TOOL) {
                parts.push("tool");
            }
            if f.has(MoveFlags::DURATION) {
                parts.push("duration");
            }
            parts.join(" ")
        }
        Instr::WaitUntil(c, t) => format!("c{c}{}", if t { " timeout" } else { "" }),
        Instr::WaitPoll(c, t) => format!("c{c} poll{}", if t { " timeout" } else { "" }),
        Instr::WaitSignal(s, t) => format!("{}{}", m.str(s), if t { " timeout" } else { "" }),
        Instr::WaitSync(s, t) => m.syncs.get(s as usize).map_or("?".into(), |x| {
            format!("y{s} {}{}", m.str(x.name), if t { " timeout" } else { "" })
        }),
        Instr::Signal(s) => m.signals_sent.get(s as usize).map_or("?".into(), |x| {
            format!("{}.{}", m.str(x.robot), m.str(x.name))
        }),
        Instr::Remote(r) => m.remotes.get(r as usize).map_or("?".into(), |x| {
            format!("r{r} {}.{}", m.str(x.robot), m.str(x.proc))
        }),
        Instr::When(h) => format!("h{h}"),
        Instr::Grip(s) | Instr::Release(s) => m
            .parts
            .get(s as usize)
            .map_or("?".into(), |x| m.str(x.part).to_string()),
        Instr::Log(f) | Instr::Fail(f) => format!("f{f}"),
        _ => String::new(),
    }
}

fn var_name(m: &Module, slot: u32) -> String {
    m.vars
        .iter()
        .find(|v| slot >= v.slot && slot < v.slot + u32::from(v.ty.width()))
        .map_or(String::new(), |v| format!(" ({})", m.str(v.name)))
}
