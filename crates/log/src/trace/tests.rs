//! The event vocabulary's names, JSON round trips and time styles.

#![allow(clippy::expect_used)]

use super::*;

#[test]
fn kinds_have_distinct_names_and_come_back_from_them() {
    for k in Kind::ALL {
        assert_eq!(Kind::from_name(k.name()), Some(k));
    }
    let mut names: Vec<_> = Kind::ALL.iter().map(|k| k.name()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), Kind::ALL.len());
    assert_eq!(Kind::from_name("wait_signal"), None);
}

#[test]
fn kinds_are_declared_in_table_order() {
    for (i, k) in Kind::ALL.into_iter().enumerate() {
        assert_eq!(k as usize, i, "{k}");
    }
    assert_eq!(
        Kind::ALL.len(),
        EVENT_NAMES.len() + Kind::ENGINE_NAMES.len()
    );
}

#[test]
fn a_vm_event_s_kind_is_named_by_the_vm_s_table() {
    // One of each VM event kind (the three waits are all `wait_until`).
    let events = [
        EventKind::MotionStart {
            command: "move_l",
            duration_ns: 1,
            zone_m: None,
            blend_m: None,
        },
        EventKind::MotionEnd {
            zone_m: None,
            programmed_m: None,
        },
        EventKind::Delay { duration_ns: 1 },
        EventKind::DelayEnd,
        EventKind::Set {
            global: 0,
            value: 0,
            ty: Type::Int,
        },
        EventKind::WaitUntil {
            cond: 0,
            deadline: None,
            poll_ns: None,
        },
        EventKind::WaitSignal {
            name: 0,
            deadline: None,
        },
        EventKind::WaitSync {
            site: 0,
            deadline: None,
        },
        EventKind::WaitEnd { timed_out: false },
        EventKind::Signal { site: 0 },
        EventKind::Grip { site: 0 },
        EventKind::Release { site: 0 },
        EventKind::Log {
            text: String::new(),
        },
        EventKind::Error {
            message: String::new(),
        },
        EventKind::EnableWhen { handler: 0 },
        EventKind::DisableWhen { proc: 0 },
        EventKind::WhenFire { handler: 0 },
        EventKind::WhenEnd { handler: 0 },
        EventKind::RemoteCall {
            site: 0,
            req: 0,
            args: Vec::new(),
        },
        EventKind::Join,
        EventKind::RemoteStart { proc: 0 },
        EventKind::RemoteEnd { proc: 0 },
        EventKind::End,
    ];
    let mut named: Vec<&str> = Vec::new();
    for e in &events {
        let kind = Kind::of(e);
        assert_eq!(kind.name(), e.name());
        assert_eq!(Kind::from_name(e.name()), Some(kind));
        named.push(e.name());
    }
    named.dedup();
    assert_eq!(
        named, EVENT_NAMES,
        "every name of the VM's table, in its order"
    );
}

#[test]
fn data_round_trips_through_json() {
    let cases = [
        (
            Kind::MotionStart,
            Data::Motion {
                command: "move_l".into(),
                duration_ns: 1_500_000_000,
                zone_m: None,
                blend_m: None,
            },
        ),
        (
            Kind::MotionStart,
            Data::Motion {
                command: "move_c".into(),
                duration_ns: 7,
                zone_m: Some(0.01),
                blend_m: Some(0.004),
            },
        ),
        (
            Kind::MotionEnd,
            Data::MotionEnd {
                zone_m: 0.005,
                programmed_m: 0.05,
            },
        ),
        (
            Kind::Set,
            Data::Set {
                global: "parts".into(),
                old: Value::Int(2),
                new: Value::Int(3),
            },
        ),
        (
            Kind::Set,
            Data::Set {
                global: "gap".into(),
                old: Value::Num(0.25),
                new: Value::Num(-1e-3),
            },
        ),
        (
            Kind::WaitUntil,
            Data::WaitCondition {
                globals: vec!["a".into(), "b".into()],
                deadline_ns: Some(7),
            },
        ),
        (
            Kind::WaitUntil,
            Data::WaitSignal {
                signal: "go".into(),
                deadline_ns: None,
            },
        ),
        (
            Kind::WaitUntil,
            Data::WaitSync {
                sync: "sstart".into(),
                tasks: vec!["r1".into(), "r2".into()],
                deadline_ns: Some(9),
            },
        ),
        (
            Kind::CollisionStart,
            Data::Collision {
                a: "r1.link_4".into(),
                b: "table".into(),
                contact: Some((0.002, [0.1, -0.2, 0.3])),
                motions: vec![
                    RobotMotion {
                        robot: "r1".into(),
                        moving: true,
                        file: Some("/x/r1.wsl".into()),
                        line: 7,
                        col: 9,
                        statement: "move_l above speed 250mm/s;".into(),
                    },
                    RobotMotion {
                        robot: "r2".into(),
                        moving: false,
                        file: None,
                        line: 0,
                        col: 0,
                        statement: String::new(),
                    },
                ],
            },
        ),
        (
            Kind::CollisionEnd,
            Data::Collision {
                a: "r1.link_4".into(),
                b: "table".into(),
                contact: None,
                motions: Vec::new(),
            },
        ),
        (
            Kind::Warning,
            Data::Issue {
                kind: IssueKind::NearMiss,
                message: "near miss".into(),
                distance_m: Some(0.00245),
                motions: vec![RobotMotion {
                    robot: "r2".into(),
                    moving: false,
                    file: Some("r2.mod".into()),
                    line: 12,
                    col: 5,
                    statement: "MoveL p20, v500, fine, tool0;".into(),
                }],
            },
        ),
        (Kind::End, Data::None),
    ];
    for (kind, data) in cases {
        let e = Event {
            time_ns: 42,
            robot: Some("r1".into()),
            kind,
            details: "d".into(),
            data,
            file: Some("/x/r1.wsl".into()),
            line: 3,
            col: 5,
        };
        assert_eq!(Event::from_json(&e.to_json()), Ok(e.clone()), "{kind}");
    }
}

/// Seconds by hand: exact to the nanosecond, trailing zeros dropped.
#[test]
fn seconds_are_exact_and_short() {
    assert_eq!(seconds(7_220_474_304), "7.220474304 s");
    assert_eq!(seconds(1_300_000_000), "1.3 s");
    assert_eq!(seconds(0), "0 s");
    assert_eq!(seconds(10_000_000), "0.01 s");
    assert_eq!(seconds(1), "0.000000001 s");
    assert_eq!(seconds(-500_000_000), "-0.5 s");
    assert_eq!(seconds(i64::MIN), "-9223372036.854775808 s");
    let motion = Data::Motion {
        command: "move_l".into(),
        duration_ns: 1_300_000_000,
        zone_m: None,
        blend_m: None,
    };
    assert_eq!(motion.text(), "move_l duration=1300000000");
    assert_eq!(motion.text_as(Times::Seconds), "move_l duration=1.3 s");
    let wait = Data::WaitSignal {
        signal: "go".into(),
        deadline_ns: Some(2_500_000_000),
    };
    assert_eq!(wait.text_as(Times::Seconds), "signal=go deadline=2.5 s");
    let e = Event {
        time_ns: 7_220_474_304,
        robot: Some("r1".into()),
        kind: Kind::Delay,
        details: "duration=1300000000".into(),
        data: Data::Delay {
            duration_ns: 1_300_000_000,
        },
        file: Some("/x/r1.wsl".into()),
        line: 3,
        col: 5,
    };
    assert_eq!(
        e.line(),
        "7220474304 r1 delay duration=1300000000 r1.wsl:3:5"
    );
    assert_eq!(
        e.line_as(Times::Seconds),
        "7.220474304 s r1 delay duration=1.3 s r1.wsl:3:5"
    );
}

#[test]
fn unknown_kinds_and_misfitting_data_are_errors() {
    let e = json!({"time_ns": 0, "kind": "teleport", "details": ""});
    assert!(Event::from_json(&e).unwrap_err().contains("`teleport`"));
    let e = json!({"time_ns": 0, "kind": "set", "data": {"global": 3}});
    assert!(Event::from_json(&e).is_err());
    let e = json!({"time_ns": 0, "kind": "end", "details": ""});
    assert_eq!(Event::from_json(&e).map(|e| e.data), Ok(Data::None));
}

#[test]
fn docs_log_md_lists_every_kind_in_table_order() {
    let doc = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/log.md"));
    let row = doc
        .lines()
        .find(|l| l.starts_with("| `kind` | string | one of "))
        .expect("docs/log.md has the `kind` row of `/events`");
    let listed: Vec<&str> = row
        .trim_start_matches("| `kind` | string | one of ")
        .split(", ")
        .map(|k| k.split('`').nth(1).unwrap_or(""))
        .collect();
    let names: Vec<&str> = Kind::ALL.iter().map(|k| k.name()).collect();
    assert_eq!(listed, names);
}
