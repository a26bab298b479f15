//! Every kind of broken robot description is an error that names the file, the element,
//! what is wrong and what to do — never a panic.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::{Path, PathBuf};

use vworks_model::urdf::{LoadOptions, load_file};
use vworks_model::{ModelError, UrdfProblem, builtin};

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("vworks-model-bad-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn link(name: &str) -> String {
    format!(r#"<link name="{name}"/>"#)
}

fn joint(name: &str, ty: &str, parent: &str, child: &str, extra: &str) -> String {
    format!(
        r#"<joint name="{name}" type="{ty}"><parent link="{parent}"/><child link="{child}"/><origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="0"/>{extra}</joint>"#
    )
}

fn robot(body: &str) -> String {
    format!(r#"<?xml version="1.0"?><robot name="bad">{body}</robot>"#)
}

fn load(file: &str, text: &str) -> Result<vworks_model::RobotModel, ModelError> {
    let d = dir();
    let p = d.join(file);
    std::fs::write(&p, text).unwrap();
    load_file(&p, &LoadOptions::default())
}

/// The kind of error a case must give.
#[derive(Debug, PartialEq)]
enum Want {
    Read,
    Parse,
    Invalid(UrdfProblem),
    Mesh,
}

fn expect_error(
    case: &str,
    want: Want,
    r: Result<vworks_model::RobotModel, ModelError>,
    file: &str,
    needles: &[&str],
) {
    let e = match r {
        Ok(_) => panic!("{case}: should fail"),
        Err(e) => e,
    };
    let got = match &e {
        ModelError::Read { .. } => Some(Want::Read),
        ModelError::Parse { .. } => Some(Want::Parse),
        ModelError::Invalid { problem, .. } => Some(Want::Invalid(*problem)),
        ModelError::Mesh { .. } => Some(Want::Mesh),
        _ => None,
    };
    assert_eq!(got, Some(want), "{case}: {e}");
    let e = e.to_string();
    assert!(
        e.contains(file),
        "{case}: the message must name the file {file}: {e}"
    );
    for n in needles {
        assert!(e.contains(n), "{case}: expected {n:?} in: {e}");
    }
}

#[test]
fn missing_file() {
    let p = dir().join("nowhere.urdf");
    expect_error(
        "missing file",
        Want::Read,
        load_file(&p, &LoadOptions::default()),
        "nowhere.urdf",
        &["cannot read"],
    );
}

#[test]
fn bad_xml() {
    expect_error(
        "bad xml",
        Want::Parse,
        load("badxml.urdf", "<robot name=\"x\"><link name=\"a\"></robot"),
        "badxml.urdf",
        &["not a valid URDF"],
    );
}

#[test]
fn unknown_joint_type() {
    let t = robot(&(link("a") + &link("b") + &joint("j_weird", "banana", "a", "b", "")));
    expect_error(
        "unknown type",
        Want::Invalid(UrdfProblem::UnknownJointType),
        load("type.urdf", &t),
        "type.urdf",
        &["joint `j_weird`", "unknown joint type `banana`", "revolute"],
    );
    let t = robot(&(link("a") + &link("b") + &joint("j_float", "floating", "a", "b", "")));
    expect_error(
        "floating",
        Want::Invalid(UrdfProblem::UnsupportedJointType),
        load("float.urdf", &t),
        "float.urdf",
        &["joint `j_float`", "not supported"],
    );
}

#[test]
fn cycle_in_the_tree() {
    // base is the root; a and b point at each other and hang off nothing.
    let t = robot(
        &(link("base")
            + &link("a")
            + &link("b")
            + &joint("ab", "revolute", "a", "b", "")
            + &joint("ba", "revolute", "b", "a", "")),
    );
    expect_error(
        "cycle",
        Want::Invalid(UrdfProblem::Cycle),
        load("cycle.urdf", &t),
        "cycle.urdf",
        &["cycle"],
    );
    // Without any root at all.
    let t = robot(
        &(link("a")
            + &link("b")
            + &joint("ab", "revolute", "a", "b", "")
            + &joint("ba", "revolute", "b", "a", "")),
    );
    expect_error(
        "cycle, no root",
        Want::Invalid(UrdfProblem::Cycle),
        load("cycle2.urdf", &t),
        "cycle2.urdf",
        &["cycle"],
    );
    // A link with two parents.
    let t = robot(
        &(link("a")
            + &link("b")
            + &link("c")
            + &joint("ac", "revolute", "a", "c", "")
            + &joint("bc", "revolute", "b", "c", "")),
    );
    expect_error(
        "two parents",
        Want::Invalid(UrdfProblem::TwoParents),
        load("parents.urdf", &t),
        "parents.urdf",
        &["joint `bc`", "already has the parent joint `ac`"],
    );
}

#[test]
fn two_roots() {
    let t = robot(&(link("a") + &link("b") + &link("c") + &joint("ab", "revolute", "a", "b", "")));
    expect_error(
        "two roots",
        Want::Invalid(UrdfProblem::SeveralRoots),
        load("roots.urdf", &t),
        "roots.urdf",
        &["2 roots", "a, c"],
    );
}

#[test]
fn missing_mesh() {
    let body = r#"<link name="a"><collision><geometry><mesh filename="package://arm/meshes/a.stl"/></geometry></collision></link>"#;
    expect_error(
        "missing mesh",
        Want::Mesh,
        load("mesh.urdf", &robot(body)),
        "mesh.urdf",
        &[
            "link `a` collision 1",
            "package://arm/meshes/a.stl",
            "not found",
            "search path",
        ],
    );
    // A mesh that exists but is not a mesh.
    let d = dir();
    std::fs::write(d.join("junk.stl"), b"this is not an stl").unwrap();
    let body = r#"<link name="a"><collision><geometry><mesh filename="junk.stl"/></geometry></collision></link>"#;
    expect_error(
        "junk mesh",
        Want::Mesh,
        load("junk.urdf", &robot(body)),
        "junk.urdf",
        &["junk.stl", "not an STL"],
    );
}

/// A mesh linked to a device (`/dev/urandom`) was read until memory ran out, as was a
/// huge file: only regular files (or links to them) within the size limit are read.
#[cfg(unix)]
#[test]
fn meshes_that_are_devices_or_too_large_are_refused_unread() {
    let d = dir();
    let mesh = |name: &str| {
        format!(
            r#"<link name="a"><collision><geometry><mesh filename="{name}"/></geometry></collision></link>"#
        )
    };
    let random = d.join("random.stl");
    let _ = std::fs::remove_file(&random);
    std::os::unix::fs::symlink("/dev/urandom", &random).unwrap();
    expect_error(
        "mesh linked to /dev/urandom",
        Want::Mesh,
        load("random.urdf", &robot(&mesh("random.stl"))),
        "random.urdf",
        &[
            "random.stl",
            "a character device, not a regular file",
            "name a file",
        ],
    );
    // Sparse: no disk space, and never read.
    let big = std::fs::File::create(d.join("big.stl")).unwrap();
    big.set_len(vworks_model::files::MAX_FILE_BYTES + 1)
        .unwrap();
    expect_error(
        "mesh over the limit",
        Want::Mesh,
        load("big.urdf", &robot(&mesh("big.stl"))),
        "big.urdf",
        &["big.stl", "larger than 256 MiB"],
    );
    // A link to a regular file is read.
    let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0 0.1 0\nvertex 0 0 0.1\nendloop\nendfacet\nendsolid t\n";
    std::fs::write(d.join("real.stl"), stl).unwrap();
    let linked = d.join("linked.stl");
    let _ = std::fs::remove_file(&linked);
    std::os::unix::fs::symlink(d.join("real.stl"), &linked).unwrap();
    let ok = load("linked.urdf", &robot(&mesh("linked.stl")));
    assert!(ok.is_ok(), "a link to a regular mesh: {:?}", ok.err());
}

#[test]
fn nan_or_inf_in_an_origin() {
    let j = joint("j2", "revolute", "a", "b", "").replace(r#"xyz="0 0 0.1""#, r#"xyz="0 nan 0.1""#);
    expect_error(
        "nan",
        Want::Invalid(UrdfProblem::NotFinite),
        load("nan.urdf", &robot(&(link("a") + &link("b") + &j))),
        "nan.urdf",
        &["joint `j2`", "<origin>", "finite"],
    );
    let j = joint("j3", "revolute", "a", "b", "").replace(r#"rpy="0 0 0""#, r#"rpy="0 inf 0""#);
    expect_error(
        "inf",
        Want::Invalid(UrdfProblem::NotFinite),
        load("inf.urdf", &robot(&(link("a") + &link("b") + &j))),
        "inf.urdf",
        &["joint `j3`", "<origin>", "finite"],
    );
}

#[test]
fn zero_axis() {
    let j = joint("j4", "revolute", "a", "b", "")
        .replace(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0 0"/>"#);
    expect_error(
        "zero axis",
        Want::Invalid(UrdfProblem::ZeroAxis),
        load("axis.urdf", &robot(&(link("a") + &link("b") + &j))),
        "axis.urdf",
        &["joint `j4`", "<axis xyz>", "non-zero"],
    );
}

#[test]
fn more_mistakes() {
    let j = joint("j5", "revolute", "a", "nowhere", "");
    expect_error(
        "missing child",
        Want::Invalid(UrdfProblem::MissingLink),
        load("child.urdf", &robot(&(link("a") + &j))),
        "child.urdf",
        &["joint `j5`", "child link `nowhere`"],
    );
    let j = joint("j6", "revolute", "a", "b", "").replace(r#"velocity="1""#, r#"velocity="0""#);
    expect_error(
        "no velocity",
        Want::Invalid(UrdfProblem::BadVelocityLimit),
        load("vel.urdf", &robot(&(link("a") + &link("b") + &j))),
        "vel.urdf",
        &["joint `j6`", "velocity"],
    );
    let j = joint("j7", "revolute", "a", "b", "")
        .replace(r#"lower="-1" upper="1""#, r#"lower="1" upper="-1""#);
    expect_error(
        "inverted limits",
        Want::Invalid(UrdfProblem::BadJointRange),
        load("lim.urdf", &robot(&(link("a") + &link("b") + &j))),
        "lim.urdf",
        &["joint `j7`", "lower"],
    );
    let body = link("a")
        + &link("b")
        + &link("c")
        + &joint("ab", "revolute", "a", "b", "")
        + &joint("ac", "revolute", "a", "c", "");
    expect_error(
        "branching",
        Want::Invalid(UrdfProblem::AmbiguousToolLink),
        load("branch.urdf", &robot(&body)),
        "branch.urdf",
        &["branches", "name the tool link", "b, c"],
    );
    let body = r#"<link name="a"><collision><geometry><box size="0.1 -0.2 0.1"/></geometry></collision></link>"#;
    expect_error(
        "negative box",
        Want::Invalid(UrdfProblem::BadSize),
        load("box.urdf", &robot(body)),
        "box.urdf",
        &["link `a` collision 1", "box size"],
    );
    let e = builtin::load("irb9999")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("irb9999") && e.contains("irb120"), "{e}");
}

#[test]
fn branching_tree_loads_with_a_named_tool() {
    let body = link("a")
        + &link("b")
        + &link("c")
        + &joint("ab", "revolute", "a", "b", "")
        + &joint("ac", "prismatic", "a", "c", "");
    let d = dir();
    let p = d.join("branch_ok.urdf");
    std::fs::write(&p, robot(&body)).unwrap();
    let m = load_file(
        Path::new(&p),
        &LoadOptions {
            tool_link: Some("c".into()),
            package_paths: vec![],
        },
    )
    .unwrap();
    assert_eq!(m.dof(), 1);
    assert_eq!(m.axis(0).name, "ac");
    assert_eq!(m.linear_axes(), 1);
}

/// Found by the `urdf` fuzz target: a joint type opened by a non-ASCII "quote" was sliced
/// inside a character (a panic). Now the joint has no type.
#[test]
fn a_type_after_a_non_ascii_character_is_an_error_not_a_panic() {
    let text = robot(&format!(
        "{}{}<joint name=\"j\" type=\u{68d}evolute\"><parent link=\"a\"/><child link=\"b\"/></joint>",
        link("a"),
        link("b")
    ));
    expect_error(
        "non-ascii quote",
        Want::Invalid(UrdfProblem::MissingJointType),
        load("quote.urdf", &text),
        "quote.urdf",
        &["joint `j`"],
    );
}

/// Two axes to `tool0` and a finger beside it (the finger's joint with `finger_extra`).
fn arm_with_finger(finger_extra: &str) -> String {
    [
        link("base"),
        link("l1"),
        link("tool0"),
        link("finger"),
        joint("j1", "revolute", "base", "l1", ""),
        joint("j2", "revolute", "l1", "tool0", ""),
        joint("jf", "revolute", "l1", "finger", finger_extra),
    ]
    .concat()
}

/// A branching tree with a link named `tool0` (the ROS-Industrial convention) needs no
/// `tool_link`; without one it is still an error that says what to do.
#[test]
fn tool0_is_the_tool_when_the_tree_branches() {
    let body = arm_with_finger("");
    let m = load("tool0.urdf", &robot(&body)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.links[m.tool_link].name, "tool0");
    assert_eq!(m.dof(), 2);
    let body = body.replace("tool0", "flange");
    expect_error(
        "branching without tool0",
        Want::Invalid(UrdfProblem::AmbiguousToolLink),
        load("notool0.urdf", &robot(&body)),
        "notool0.urdf",
        &["the tree branches", "tool_link", "tool0"],
    );
}

/// `acceleration`, `deceleration` and `jerk` are read from a URDF 1.0 file (urdf-rs reads
/// them only from 1.2); a deceleration below the acceleration limits both (symmetric
/// profiles); a value that is not a positive number is an error naming the joint.
#[test]
fn dynamic_limits_are_read_whatever_the_version() {
    let limits = |attrs: &str| {
        robot(&[
            link("a"),
            link("b"),
            format!(
                r#"<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="2" effort="0" {attrs}/></joint>"#
            ),
        ]
        .concat())
    };
    let m = load("acc.urdf", &limits(r#"acceleration="3.5" jerk="40""#)).unwrap();
    assert_eq!(m.axis(0).max_accel, 3.5);
    assert_eq!(m.axis(0).max_jerk, Some(40.0));
    let m = load(
        "dec.urdf",
        &limits(r#"acceleration="3.5" deceleration="1.25""#),
    )
    .unwrap();
    assert_eq!(m.axis(0).max_accel, 1.25);
    let m = load("none.urdf", &limits("")).unwrap();
    assert!((m.axis(0).max_accel - 2.0 / 0.3).abs() < 1e-12);
    assert_eq!(m.axis(0).max_jerk, None);
    expect_error(
        "zero acceleration",
        Want::Invalid(UrdfProblem::BadDynamicLimit),
        load("zero.urdf", &limits(r#"acceleration="0""#)),
        "zero.urdf",
        &["joint `j`", "acceleration limit is 0"],
    );
    expect_error(
        "negative jerk",
        Want::Invalid(UrdfProblem::BadDynamicLimit),
        load("jerk.urdf", &limits(r#"jerk="-5""#)),
        "jerk.urdf",
        &["joint `j`", "jerk limit is -5", "greater than 0"],
    );
    expect_error(
        "infinite jerk",
        Want::Invalid(UrdfProblem::BadDynamicLimit),
        load("inf.urdf", &limits(r#"jerk="inf""#)),
        "inf.urdf",
        &["joint `j`", "jerk limit is inf"],
    );
    expect_error(
        "not a number",
        Want::Invalid(UrdfProblem::BadDynamicLimit),
        load("nan.urdf", &limits(r#"deceleration="fast""#)),
        "nan.urdf",
        &["joint `j`", "deceleration limit is NaN"],
    );
}

/// A `<mimic>` joint on the chain to the tool would silently have become an independent
/// axis: an error naming it. Off the chain (a gripper finger) it is accepted.
#[test]
fn a_mimic_joint_on_the_tool_chain_is_an_error() {
    let mimic = r#"<mimic joint="j1" multiplier="1"/>"#;
    let body = [
        link("base"),
        link("l1"),
        link("l2"),
        joint("j1", "revolute", "base", "l1", ""),
        joint("j2", "revolute", "l1", "l2", mimic),
    ]
    .concat();
    expect_error(
        "mimic on the chain",
        Want::Invalid(UrdfProblem::MimicOnToolChain),
        load("mimic.urdf", &robot(&body)),
        "mimic.urdf",
        &["joint `j2`", "mimics another joint"],
    );
    load("finger.urdf", &robot(&arm_with_finger(mimic))).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn deeply_nested_elements_are_an_error_not_a_stack_overflow() {
    // 20,000 elements one inside the next: urdf-rs walks the tree recursively (its
    // `convert_versioned`, the XML printer, the deserializer), which overflowed the stack.
    let n = 20_000;
    let t = robot(&(link("a") + &"<x>".repeat(n) + &"</x>".repeat(n)));
    expect_error(
        "nesting",
        Want::Invalid(UrdfProblem::TooDeep),
        load("deep.urdf", &t),
        "deep.urdf",
        &["element `<x>` at line 1", "64"],
    );
    // At the limit (an element inside 63 others, <robot> the outermost) the file is read;
    // comments, quoted `>` and `/>`, and self-closing elements do not count.
    let inner = 63;
    let t = robot(
        &(link("a")
            + "<!-- <y><y><y> -->"
            + &r#"<x note="a > b" other='c/>'>"#.repeat(inner - 1)
            + "<y/>"
            + &"</x>".repeat(inner - 1)),
    );
    let m = load("at_limit.urdf", &t).unwrap();
    assert_eq!(m.links.len(), 1);
    let t = robot(&(link("a") + &"<x>".repeat(inner + 1) + &"</x>".repeat(inner + 1)));
    expect_error(
        "one too deep",
        Want::Invalid(UrdfProblem::TooDeep),
        load("too_deep.urdf", &t),
        "too_deep.urdf",
        &["65 deep", "64"],
    );
}
