//! URDF import (through urdf-rs), with every check a robot description needs before
//! vworks trusts it: one root, no cycles, finite origins, non-zero axes, usable limits,
//! meshes that exist and parse. Each problem is a [`ModelError`] naming the file and the
//! element.
//!
//! Mesh paths are relative to the URDF file; `package://PKG/REST` is looked up as
//! `DIR/PKG/REST` for the URDF's folder and every folder of the search path.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use parry3d::math::Vector;
use parry3d::shape::SharedShape;

use crate::error::{ModelError, UrdfProblem};
use crate::files::{Disk, Files};
use crate::math::{Iso, V3, norm};
use crate::mesh;
use crate::model::{
    AxisDir, DEFAULT_ACCEL_TIME, Geometry, Joint, JointKind, Link, LinkShape, RobotModel, TcpLimits,
};

/// How to load a URDF.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// The tool (flange) link. Without one: the chain's end, or `tool0` (the ROS-Industrial
    /// convention) when the tree branches; a branching tree without `tool0` is an error.
    pub tool_link: Option<String>,
    /// Folders searched for `package://` meshes (besides the URDF's own folder).
    pub package_paths: Vec<PathBuf>,
}

/// Loads a URDF file.
pub fn load_file(path: &Path, opts: &LoadOptions) -> Result<RobotModel, ModelError> {
    load_file_with(path, opts, &Disk)
}

/// Loads a URDF file, reading it and its meshes from `files`.
pub fn load_file_with(
    path: &Path,
    opts: &LoadOptions,
    files: &dyn Files,
) -> Result<RobotModel, ModelError> {
    let file = path.display().to_string();
    let read = |reason: String| ModelError::Read {
        file: file.clone(),
        reason,
    };
    let bytes = files.read(path).map_err(|e| read(e.to_string()))?;
    let text = String::from_utf8(bytes).map_err(|e| read(format!("not UTF-8 text: {e}")))?;
    load_str_with(&text, &file, path.parent(), opts, files)
}

/// Loads URDF text; `file` names it in errors, `dir` is where relative meshes are.
pub fn load_str(
    text: &str,
    file: &str,
    dir: Option<&Path>,
    opts: &LoadOptions,
) -> Result<RobotModel, ModelError> {
    load_str_with(text, file, dir, opts, &Disk)
}

/// [`load_str`], reading meshes from `files`.
pub fn load_str_with(
    text: &str,
    file: &str,
    dir: Option<&Path>,
    opts: &LoadOptions,
    files: &dyn Files,
) -> Result<RobotModel, ModelError> {
    let invalid =
        |problem: UrdfProblem, element: String, message: String, help: &str| ModelError::Invalid {
            problem,
            file: file.to_string(),
            element,
            message,
            help: help.to_string(),
        };
    // urdf-rs walks the element tree recursively: nesting is bounded before it sees it.
    check_nesting(text, file)?;
    // Joint elements read from the text itself (comments and references left out).
    let stripped = strip_blocks(text);
    let elements = joint_elements(&stripped);
    check_joint_types(&elements, file)?;
    // urdf-rs reads `acceleration`, `deceleration` and `jerk` only from URDF 1.2 files;
    // vworks reads them whatever the version (docs/models.md).
    let dynamics = limit_attributes(&elements);
    let robot = urdf_rs::read_from_string(text).map_err(|e| ModelError::Parse {
        file: file.to_string(),
        reason: e.to_string(),
    })?;

    // Links by name.
    let mut by_name: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, l) in robot.links.iter().enumerate() {
        if by_name.insert(l.name.as_str(), i).is_some() {
            return Err(invalid(
                UrdfProblem::DuplicateLink,
                format!("link `{}`", l.name),
                "is declared twice".into(),
                "give every link a unique name",
            ));
        }
    }
    if robot.links.is_empty() {
        return Err(invalid(
            UrdfProblem::NoLinks,
            "robot".into(),
            "has no links".into(),
            "a URDF needs at least one <link>",
        ));
    }

    // Joints: endpoints, one parent per link, finite numbers.
    let mut parent_of: Vec<Option<usize>> = vec![None; robot.links.len()];
    for (ji, j) in robot.joints.iter().enumerate() {
        let el = || format!("joint `{}`", j.name);
        let find = |name: &str, role: &str| {
            by_name.get(name).copied().ok_or_else(|| {
                invalid(
                    UrdfProblem::MissingLink,
                    el(),
                    format!("its {role} link `{name}` does not exist"),
                    "name a <link> of this file",
                )
            })
        };
        find(&j.parent.link, "parent")?;
        let c = find(&j.child.link, "child")?;
        if let Some(other) = parent_of[c] {
            return Err(invalid(
                UrdfProblem::TwoParents,
                el(),
                format!(
                    "link `{}` already has the parent joint `{}`",
                    j.child.link, robot.joints[other].name
                ),
                "a URDF is a tree: every link has at most one parent joint",
            ));
        }
        parent_of[c] = Some(ji);
        let o = &j.origin;
        if o.xyz.0.iter().chain(o.rpy.0.iter()).any(|x| !x.is_finite()) {
            return Err(invalid(
                UrdfProblem::NotFinite,
                el(),
                "its <origin> has a value that is not a finite number".into(),
                "write numbers for xyz and rpy (no nan or inf)",
            ));
        }
        let a = j.axis.xyz.0;
        let moves = j.joint_type != urdf_rs::JointType::Fixed;
        if moves && (a.iter().any(|x| !x.is_finite()) || norm(a) < 1e-12) {
            return Err(invalid(
                UrdfProblem::ZeroAxis,
                el(),
                format!("its <axis xyz> is {:?}", a),
                "give a non-zero direction, e.g. <axis xyz=\"0 0 1\"/>",
            ));
        }
    }

    // Exactly one root, and every link reachable from it.
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|i| parent_of[*i].is_none())
        .collect();
    if roots.len() > 1 {
        let names: Vec<&str> = roots
            .iter()
            .map(|r| robot.links[*r].name.as_str())
            .collect();
        return Err(invalid(
            UrdfProblem::SeveralRoots,
            format!("link `{}`", names[1]),
            format!("the tree has {} roots ({})", roots.len(), names.join(", ")),
            "connect every link to one base link with a joint",
        ));
    }
    let Some(&root) = roots.first() else {
        return Err(invalid(
            UrdfProblem::Cycle,
            "robot".into(),
            "every link has a parent, so the joints form a cycle".into(),
            "remove the joint that closes the loop",
        ));
    };
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (ji, j) in robot.joints.iter().enumerate() {
        let p = by_name[j.parent.link.as_str()];
        children[p].push(ji);
    }
    // Breadth-first from the root gives parents before children.
    let mut order = vec![root];
    let mut k = 0;
    while k < order.len() {
        let l = order[k];
        for &ji in &children[l] {
            order.push(by_name[robot.joints[ji].child.link.as_str()]);
        }
        k += 1;
    }
    if order.len() != robot.links.len() {
        let stray = (0..robot.links.len())
            .find(|i| !order.contains(i))
            .unwrap_or(0);
        return Err(invalid(
            UrdfProblem::Cycle,
            format!("link `{}`", robot.links[stray].name),
            "is part of a cycle of joints, not reachable from the base".into(),
            "a URDF is a tree: remove the joint that closes the loop",
        ));
    }
    let new_index: BTreeMap<usize, usize> =
        order.iter().enumerate().map(|(n, o)| (*o, n)).collect();

    // Tool link: named, or the end of the chain.
    let tool_old = match &opts.tool_link {
        Some(name) => *by_name.get(name.as_str()).ok_or_else(|| {
            invalid(
                UrdfProblem::UnknownToolLink,
                format!("tool link `{name}`"),
                "is not a link of this robot".into(),
                "name one of its links as the tool",
            )
        })?,
        None => {
            let mut l = root;
            loop {
                match children[l].len() {
                    0 => break l,
                    1 => l = by_name[robot.joints[children[l][0]].child.link.as_str()],
                    // ROS-Industrial's convention: every industrial URDF has a `tool0`.
                    _ if by_name.contains_key("tool0") => break by_name["tool0"],
                    _ => {
                        let leaves: Vec<&str> = (0..robot.links.len())
                            .filter(|i| children[*i].is_empty())
                            .map(|i| robot.links[i].name.as_str())
                            .collect();
                        return Err(invalid(
                            UrdfProblem::AmbiguousToolLink,
                            format!("link `{}`", robot.links[l].name),
                            "the tree branches here, so the tool link is ambiguous".into(),
                            &format!(
                                "name the tool link in the workcell (`tool_link`, one of: {}), or call it `tool0`",
                                leaves.join(", ")
                            ),
                        ));
                    }
                }
            }
        }
    };

    // Joints in child order, with limits.
    let mut joints = Vec::with_capacity(robot.joints.len());
    for &old_child in order.iter().skip(1) {
        let Some(ji) = parent_of[old_child] else {
            continue;
        };
        let j = &robot.joints[ji];
        let el = || format!("joint `{}`", j.name);
        let kind = match j.joint_type {
            urdf_rs::JointType::Revolute => JointKind::Revolute,
            urdf_rs::JointType::Continuous => JointKind::Continuous,
            urdf_rs::JointType::Prismatic => JointKind::Prismatic,
            urdf_rs::JointType::Fixed => JointKind::Fixed,
            _ => {
                return Err(invalid(
                    UrdfProblem::UnsupportedJointType,
                    el(),
                    "has a type vworks does not support".into(),
                    "use revolute, continuous, prismatic or fixed",
                ));
            }
        };
        let a = j.axis.xyz.0;
        let n = norm(a);
        let axis = if kind.is_movable() {
            [a[0] / n, a[1] / n, a[2] / n]
        } else {
            [0.0, 0.0, 1.0]
        };
        let lim = &j.limit;
        let (lower, upper) = match kind {
            JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
            JointKind::Fixed => (0.0, 0.0),
            _ => {
                if !lim.lower.is_finite() || !lim.upper.is_finite() || lim.lower > lim.upper {
                    return Err(invalid(
                        UrdfProblem::BadJointRange,
                        el(),
                        format!(
                            "its limits lower={} upper={} are not a finite range",
                            lim.lower, lim.upper
                        ),
                        "write <limit lower=\"…\" upper=\"…\" velocity=\"…\"/> with lower ≤ upper",
                    ));
                }
                (lim.lower, lim.upper)
            }
        };
        let (max_velocity, max_accel, max_jerk) = if kind.is_movable() {
            if !(lim.velocity.is_finite() && lim.velocity > 0.0) {
                return Err(invalid(
                    UrdfProblem::BadVelocityLimit,
                    el(),
                    format!("its velocity limit is {}", lim.velocity),
                    "a moving joint needs <limit velocity=\"…\"/> greater than 0",
                ));
            }
            let extra = dynamics.get(j.name.as_str());
            let given = |name: &str, value: Option<f64>| -> Result<Option<f64>, ModelError> {
                match value {
                    Some(v) if !(v.is_finite() && v > 0.0) => Err(invalid(
                        UrdfProblem::BadDynamicLimit,
                        el(),
                        format!("its {name} limit is {v}"),
                        &format!("write <limit {name}=\"…\"/> greater than 0, or leave it out"),
                    )),
                    other => Ok(other),
                }
            };
            let acc = given("acceleration", extra.and_then(|d| d.acceleration))?;
            let dec = given("deceleration", extra.and_then(|d| d.deceleration))?;
            let acc = match (acc, dec) {
                (Some(a), Some(d)) => a.min(d),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => lim.velocity / DEFAULT_ACCEL_TIME,
            };
            let jerk = given("jerk", extra.and_then(|d| d.jerk))?;
            (lim.velocity, acc, jerk)
        } else {
            (0.0, 0.0, None)
        };
        joints.push(Joint {
            name: j.name.clone(),
            kind,
            parent: new_index[&by_name[j.parent.link.as_str()]],
            child: new_index[&old_child],
            origin: Iso::from_xyz_rpy(j.origin.xyz.0, j.origin.rpy.0),
            axis,
            dir: AxisDir::new(axis),
            lower,
            upper,
            max_velocity,
            max_accel,
            max_jerk,
            axis_index: None,
        });
    }

    // Links with shapes.
    let mut links = Vec::with_capacity(order.len());
    for &old in &order {
        let l = &robot.links[old];
        let mut shapes = Vec::new();
        for (ci, c) in l.collision.iter().enumerate() {
            let el = format!("link `{}` collision {}", l.name, ci + 1);
            let o = &c.origin;
            if o.xyz.0.iter().chain(o.rpy.0.iter()).any(|x| !x.is_finite()) {
                return Err(invalid(
                    UrdfProblem::NotFinite,
                    el,
                    "its <origin> has a value that is not a finite number".into(),
                    "write numbers for xyz and rpy",
                ));
            }
            let origin = Iso::from_xyz_rpy(o.xyz.0, o.rpy.0);
            let geometry = geometry(&c.geometry, file, dir, &el, opts, files)?;
            shapes.push(build_shape(geometry, origin, file, &el)?);
        }
        let index = links.len();
        links.push(Link {
            name: l.name.clone(),
            parent_joint: joints.iter().position(|j| j.child == index),
            shapes,
        });
    }

    // The axes: movable joints from the root to the tool.
    let tool_link = new_index[&tool_old];
    let mut path = Vec::new();
    let mut l = tool_link;
    while let Some(j) = links[l].parent_joint {
        path.push(j);
        l = joints[j].parent;
    }
    path.reverse();
    let axes: Vec<usize> = path
        .into_iter()
        .filter(|j| joints[*j].kind.is_movable())
        .collect();
    if axes.len() > 12 {
        return Err(invalid(
            UrdfProblem::TooManyAxes,
            format!("link `{}`", links[tool_link].name),
            format!("the chain to the tool has {} axes", axes.len()),
            "vworks robots have at most 12 axes; split the cell into several robots",
        ));
    }
    for (i, j) in axes.iter().enumerate() {
        joints[*j].axis_index = Some(i);
    }
    // A <mimic> joint on the way to the tool would silently become an axis of its own
    // (vworks does not couple joints); off that path it stays at 0 like any other joint.
    for &j in &axes {
        let name = &joints[j].name;
        if robot
            .joints
            .iter()
            .any(|rj| rj.name == *name && rj.mimic.is_some())
        {
            return Err(invalid(
                UrdfProblem::MimicOnToolChain,
                format!("joint `{name}`"),
                "mimics another joint, and is on the chain to the tool: vworks would move it as an axis of its own".into(),
                "give it its own axis (remove <mimic>), or choose a tool link whose chain does not pass through it",
            ));
        }
    }
    let mut model = RobotModel {
        name: robot.name.clone(),
        source: file.to_string(),
        links,
        joints,
        axes,
        tool_link,
        wrist: None,
        tcp: tcp_limits(&stripped, file)?,
        chain_cache: Vec::new(),
    };
    model.chain_cache = model.chain();
    model.wrist = crate::ik::SphericalWrist::detect(&model);
    Ok(model)
}

/// How deep elements may nest in a URDF (`<robot>` is at depth 1). URDFs nest 5 deep
/// (robot, link, collision, geometry, mesh), a few more with `<gazebo>` plugin blocks;
/// urdf-rs reads the tree recursively (its version conversion, the XML printer and the
/// deserializer), and 20,000 levels overflowed the stack.
pub const MAX_NESTING: usize = 64;

/// Rejects elements nested deeper than [`MAX_NESTING`], by one streaming pass over the
/// text (comments, CDATA, processing instructions, declarations and quoted attribute
/// values skipped; self-closing elements count at their depth, and do not nest).
fn check_nesting(text: &str, file: &str) -> Result<(), ModelError> {
    let b = text.as_bytes();
    let skip_to = |from: usize, end: &str| {
        text[from..]
            .find(end)
            .map_or(b.len(), |k| from + k + end.len())
    };
    let (mut depth, mut at) = (0usize, 0usize);
    while let Some(k) = text[at..].find('<') {
        let start = at + k;
        let rest = &text[start..];
        if rest.starts_with("<!--") {
            at = skip_to(start, "-->");
        } else if rest.starts_with("<![CDATA[") {
            at = skip_to(start, "]]>");
        } else if rest.starts_with("<?") {
            at = skip_to(start, "?>");
        } else if rest.starts_with("<!") || rest.starts_with("</") {
            depth = depth.saturating_sub(usize::from(rest.starts_with("</")));
            at = skip_to(start, ">");
        } else {
            // A start tag: up to its `>` outside quotes.
            let mut quote = None;
            let mut end = b.len();
            for (i, &c) in b.iter().enumerate().skip(start + 1) {
                match (quote, c) {
                    (None, b'"' | b'\'') => quote = Some(c),
                    (Some(q), _) if c == q => quote = None,
                    (None, b'>') => {
                        end = i;
                        break;
                    }
                    _ => {}
                }
            }
            if depth + 1 > MAX_NESTING {
                let name: String = rest[1..]
                    .chars()
                    .take_while(|c| !c.is_whitespace() && !matches!(c, '>' | '/'))
                    .take(40)
                    .collect();
                let line = 1 + text[..start].bytes().filter(|&c| c == b'\n').count();
                return Err(ModelError::Invalid {
                    problem: UrdfProblem::TooDeep,
                    file: file.to_string(),
                    element: format!("element `<{name}>` at line {line}"),
                    message: format!(
                        "is nested {} deep, deeper than the {MAX_NESTING} levels vworks reads",
                        depth + 1
                    ),
                    help: "a URDF's elements nest about 5 deep (robot, link, collision, geometry, mesh); look for elements that are never closed".into(),
                });
            }
            if end < b.len() && b[end - 1] != b'/' {
                depth += 1;
            }
            at = (end + 1).min(b.len());
        }
    }
    Ok(())
}

/// A `<joint …>` element of the text: its start tag's attributes, and its body up to its
/// end tag (or the next joint).
struct JointElement<'t> {
    tag: &'t str,
    body: &'t str,
}

/// Every `<joint …>` element of `text` (stripped of comments and references).
fn joint_elements(text: &str) -> Vec<JointElement<'_>> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("<joint") {
        let after = &rest[i + 6..];
        rest = after;
        if !after.starts_with(|c: char| c.is_whitespace()) {
            continue;
        }
        let tag_end = after.find('>').unwrap_or(after.len());
        let body_end = after
            .find("</joint>")
            .or_else(|| after.find("<joint"))
            .unwrap_or(after.len());
        out.push(JointElement {
            tag: &after[..tag_end],
            body: &after[..body_end.max(tag_end)],
        });
    }
    out
}

/// Rejects joint types before urdf-rs does, so the error names the joint.
fn check_joint_types(elements: &[JointElement<'_>], file: &str) -> Result<(), ModelError> {
    for j in elements {
        // (A quote that is not ASCII once sliced inside a character: found by fuzzing.)
        let attr = |key: &str| attribute(j.tag, key);
        let name = attr("name").unwrap_or("?");
        match attr("type") {
            Some("revolute" | "continuous" | "prismatic" | "fixed") => {}
            Some(t @ ("floating" | "planar" | "spherical")) => {
                return Err(ModelError::Invalid {
                    problem: UrdfProblem::UnsupportedJointType,
                    file: file.into(),
                    element: format!("joint `{name}`"),
                    message: format!("type `{t}` is not supported"),
                    help: "robot joints in vworks are revolute, continuous, prismatic or fixed"
                        .into(),
                });
            }
            Some(t) => {
                return Err(ModelError::Invalid {
                    problem: UrdfProblem::UnknownJointType,
                    file: file.into(),
                    element: format!("joint `{name}`"),
                    message: format!("unknown joint type `{t}`"),
                    help: "the types are revolute, continuous, prismatic and fixed".into(),
                });
            }
            None => {
                return Err(ModelError::Invalid {
                    problem: UrdfProblem::MissingJointType,
                    file: file.into(),
                    element: format!("joint `{name}`"),
                    message: "has no type".into(),
                    help: "add type=\"revolute\" (or continuous, prismatic, fixed)".into(),
                });
            }
        }
    }
    Ok(())
}

/// The dynamic limits of a joint's `<limit>` element, read from the text.
#[derive(Clone, Copy, Debug, Default)]
struct Dynamics {
    acceleration: Option<f64>,
    deceleration: Option<f64>,
    jerk: Option<f64>,
}

/// Each joint's `acceleration`, `deceleration` and `jerk` limit attributes (a value that
/// is not a number reads as NaN, which the caller rejects).
fn limit_attributes(elements: &[JointElement<'_>]) -> BTreeMap<String, Dynamics> {
    let mut out = BTreeMap::new();
    for j in elements {
        let (Some(name), Some(l)) = (attribute(j.tag, "name"), j.body.find("<limit")) else {
            continue;
        };
        let limit = &j.body[l..];
        let limit = &limit[..limit.find('>').unwrap_or(limit.len())];
        let num =
            |key: &str| attribute(limit, key).map(|v| v.trim().parse::<f64>().unwrap_or(f64::NAN));
        out.insert(
            name.to_string(),
            Dynamics {
                acceleration: num("acceleration"),
                deceleration: num("deceleration"),
                jerk: num("jerk"),
            },
        );
    }
    out
}

/// The value of attribute `key` in the text of one tag (`key="v"` or `key='v'`, with the
/// key standing alone: `acceleration` is not found inside `deceleration`).
fn attribute<'t>(tag: &'t str, key: &str) -> Option<&'t str> {
    let mut from = 0;
    while let Some(k) = tag[from..].find(key) {
        let start = from + k;
        from = start + key.len();
        let before_ok = tag[..start].ends_with(|c: char| c.is_whitespace());
        let rest = tag[from..].trim_start();
        if !before_ok || !rest.starts_with('=') {
            continue;
        }
        let v = rest[1..].trim_start();
        let q = v.chars().next()?;
        if q != '"' && q != '\'' {
            return None;
        }
        let v = &v[1..];
        return Some(&v[..v.find(q)?]);
    }
    None
}

/// The model's TCP limits: the attributes of a `<tcp_limits>` element (a vworks extension
/// other URDF readers ignore), each positive and finite.
fn tcp_limits(stripped: &str, file: &str) -> Result<TcpLimits, ModelError> {
    let bad = |message: String, help: &str| ModelError::Invalid {
        problem: UrdfProblem::BadDynamicLimit,
        file: file.to_string(),
        element: "tcp_limits".into(),
        message,
        help: help.to_string(),
    };
    // Elements named exactly `tcp_limits` (not `<tcp_limits_note …>`).
    let mut tags = stripped.match_indices("<tcp_limits").filter_map(|(at, _)| {
        let rest = &stripped[at + "<tcp_limits".len()..];
        rest.starts_with(|c: char| c.is_whitespace() || c == '/' || c == '>')
            .then(|| &rest[..rest.find('>').unwrap_or(rest.len())])
    });
    let Some(tag) = tags.next() else {
        return Ok(TcpLimits::default());
    };
    if tags.next().is_some() {
        return Err(bad(
            "is given twice".into(),
            "give the robot one <tcp_limits speed=\"…\" acceleration=\"…\"/>",
        ));
    }
    // Every attribute is one vworks knows.
    let mut rest = tag.trim_start();
    while let Some(eq) = rest.find('=') {
        let key = rest[..eq].trim();
        if !key.is_empty() && key != "speed" && key != "acceleration" {
            return Err(bad(
                format!("has an attribute `{key}` vworks does not know"),
                "write speed=\"…\" (m/s) and acceleration=\"…\" (m/s²)",
            ));
        }
        let after = rest[eq + 1..].trim_start();
        let Some(q) = after.chars().next().filter(|c| *c == '"' || *c == '\'') else {
            break;
        };
        let Some(close) = after[1..].find(q) else {
            break;
        };
        rest = &after[close + 2..];
    }
    let value = |key: &str, unit: &str| -> Result<Option<f64>, ModelError> {
        let Some(text) = attribute(tag, key) else {
            return Ok(None);
        };
        match text.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(Some(v)),
            _ => Err(bad(
                format!("its {key} is `{text}`"),
                &format!("write {key}=\"…\" as a number of {unit} greater than 0, or leave it out"),
            )),
        }
    };
    Ok(TcpLimits {
        speed: value("speed", "m/s")?,
        accel: value("acceleration", "m/s²")?,
    })
}

/// The text without comments and without `<transmission>`/`<gazebo>` blocks, whose
/// `<joint name=…>` elements are references, not joints.
fn strip_blocks(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    loop {
        let next = [
            ("<!--", "-->"),
            ("<transmission", "</transmission>"),
            ("<gazebo", "</gazebo>"),
        ]
        .iter()
        .filter_map(|(open, close)| rest.find(open).map(|i| (i, *close)))
        .min_by_key(|(i, _)| *i);
        let Some((i, close)) = next else {
            out.push_str(rest);
            return out;
        };
        out.push_str(&rest[..i]);
        rest = match rest[i..].find(close) {
            Some(j) => &rest[i + j + close.len()..],
            None => "",
        };
    }
}

fn positive(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite() && *v > 0.0)
}

fn geometry(
    g: &urdf_rs::Geometry,
    file: &str,
    dir: Option<&Path>,
    el: &str,
    opts: &LoadOptions,
    files: &dyn Files,
) -> Result<Geometry, ModelError> {
    let bad = |what: &str| ModelError::Invalid {
        problem: UrdfProblem::BadSize,
        file: file.into(),
        element: el.into(),
        message: format!("its {what} must be positive, finite numbers"),
        help: "sizes are in metres".into(),
    };
    Ok(match g {
        urdf_rs::Geometry::Box { size } => {
            if !positive(&size.0) {
                return Err(bad("box size"));
            }
            Geometry::Box {
                half: [size[0] / 2.0, size[1] / 2.0, size[2] / 2.0],
            }
        }
        urdf_rs::Geometry::Cylinder { radius, length } => {
            if !positive(&[*radius, *length]) {
                return Err(bad("cylinder radius and length"));
            }
            Geometry::Cylinder {
                radius: *radius,
                length: *length,
            }
        }
        urdf_rs::Geometry::Capsule { radius, length } => {
            if !(positive(&[*radius]) && length.is_finite() && *length >= 0.0) {
                return Err(bad("capsule radius and length"));
            }
            Geometry::Capsule {
                radius: *radius,
                length: *length,
            }
        }
        urdf_rs::Geometry::Sphere { radius } => {
            if !positive(&[*radius]) {
                return Err(bad("sphere radius"));
            }
            Geometry::Sphere { radius: *radius }
        }
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let scale: V3 = scale.as_ref().map_or([1.0; 3], |s| s.0);
            if !positive(&scale) {
                return Err(bad("mesh scale"));
            }
            let mesh_err = |message: String| ModelError::Mesh {
                file: file.into(),
                element: el.into(),
                mesh: filename.clone(),
                message,
            };
            let candidates = mesh_candidates(filename, dir, &opts.package_paths);
            let mut found = None;
            for p in &candidates {
                match files.read(p) {
                    Ok(bytes) => {
                        found = Some((p, bytes));
                        break;
                    }
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                    // A folder of that name, say: not this candidate.
                    Err(e) if e.kind() == std::io::ErrorKind::IsADirectory => {}
                    Err(e) => return Err(mesh_err(format!("cannot read {}: {e}", p.display()))),
                }
            }
            let Some((path, bytes)) = found else {
                let looked: Vec<String> =
                    candidates.iter().map(|p| p.display().to_string()).collect();
                return Err(mesh_err(format!(
                    "not found (looked for {}); put the mesh there or add its package's parent folder to the search path (the workcell's `package_path`, or ROS_PACKAGE_PATH)",
                    looked.join(", ")
                )));
            };
            let points = mesh::read_vertices(&bytes, filename, scale)
                .map_err(|m| mesh_err(format!("{} ({})", m, path.display())))?;
            Geometry::Hull {
                source: path.display().to_string(),
                points,
            }
        }
    })
}

fn mesh_candidates(filename: &str, dir: Option<&Path>, packages: &[PathBuf]) -> Vec<PathBuf> {
    let base = dir.map(Path::to_path_buf).unwrap_or_default();
    if let Some(rest) = filename.strip_prefix("package://") {
        let mut v = vec![base.join(rest)];
        v.extend(packages.iter().map(|p| p.join(rest)));
        if let Some((_, inner)) = rest.split_once('/') {
            v.push(base.join(inner));
        }
        return v;
    }
    if let Some(abs) = filename.strip_prefix("file://") {
        return vec![PathBuf::from(abs)];
    }
    vec![base.join(filename)]
}

/// Builds the parry shape of a collision body once.
pub fn build_shape(
    geometry: Geometry,
    origin: Iso,
    file: &str,
    el: &str,
) -> Result<LinkShape, ModelError> {
    let mut local_pose = origin.to_pose();
    let shape = match &geometry {
        Geometry::Box { half } => SharedShape::cuboid(half[0], half[1], half[2]),
        Geometry::Sphere { radius } => SharedShape::ball(*radius),
        Geometry::Capsule { radius, length } => SharedShape::capsule_z(*length / 2.0, *radius),
        Geometry::Cylinder { radius, length } => {
            // parry's cylinders stand on y; URDF's on z.
            let turn = Iso::from_xyz_rpy([0.0; 3], [std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
            local_pose = origin.mul(&turn).to_pose();
            SharedShape::cylinder(*length / 2.0, *radius)
        }
        Geometry::Hull { points, .. } => {
            let pts: Vec<Vector> = points
                .iter()
                .map(|p| Vector::new(p[0], p[1], p[2]))
                .collect();
            SharedShape::convex_hull(&pts).ok_or_else(|| ModelError::Invalid {
                problem: UrdfProblem::DegenerateMesh,
                file: file.into(),
                element: el.into(),
                message: "the mesh is flat or degenerate, so it has no convex hull".into(),
                help: "use a closed mesh with volume, or a box/capsule".into(),
            })?
        }
    };
    Ok(LinkShape {
        geometry,
        origin,
        shape,
        local_pose,
    })
}
