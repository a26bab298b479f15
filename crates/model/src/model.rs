//! The robot model: a tree of links joined by joints, with the chain of axes from the root
//! to the tool link, limits, and collision shapes — and its forward kinematics.

use parry3d::math::{Pose, Vector};
use parry3d::shape::SharedShape;

use crate::math::{Iso, M3, V3, axis_angle, mat_mul};

/// How a joint moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rigid.
    Fixed,
    /// Rotates about its axis within limits.
    Revolute,
    /// Rotates about its axis without limits.
    Continuous,
    /// Slides along its axis.
    Prismatic,
}

impl JointKind {
    /// True for joints that move.
    pub fn is_movable(self) -> bool {
        self != JointKind::Fixed
    }
}

/// The direction of a joint axis, with fast paths for the coordinate axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum AxisDir {
    X(f64),
    Y(f64),
    Z(f64),
    Any(V3),
}

impl AxisDir {
    pub(crate) fn new(a: V3) -> AxisDir {
        match a {
            [x, 0.0, 0.0] if x.abs() == 1.0 => AxisDir::X(x),
            [0.0, y, 0.0] if y.abs() == 1.0 => AxisDir::Y(y),
            [0.0, 0.0, z] if z.abs() == 1.0 => AxisDir::Z(z),
            _ => AxisDir::Any(a),
        }
    }

    /// The rotation by `q` about this axis.
    #[inline]
    pub(crate) fn rotation(self, q: f64) -> M3 {
        match self {
            AxisDir::X(s) => {
                let (sn, c) = (s * q).sin_cos();
                [[1.0, 0.0, 0.0], [0.0, c, -sn], [0.0, sn, c]]
            }
            AxisDir::Y(s) => {
                let (sn, c) = (s * q).sin_cos();
                [[c, 0.0, sn], [0.0, 1.0, 0.0], [-sn, 0.0, c]]
            }
            AxisDir::Z(s) => {
                let (sn, c) = (s * q).sin_cos();
                [[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]]
            }
            AxisDir::Any(a) => axis_angle(a, q),
        }
    }

    pub(crate) fn vector(self) -> V3 {
        match self {
            AxisDir::X(s) => [s, 0.0, 0.0],
            AxisDir::Y(s) => [0.0, s, 0.0],
            AxisDir::Z(s) => [0.0, 0.0, s],
            AxisDir::Any(a) => a,
        }
    }
}

/// A joint between a parent and a child link.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Name in the URDF.
    pub name: String,
    /// How it moves.
    pub kind: JointKind,
    /// Parent link index.
    pub parent: usize,
    /// Child link index.
    pub child: usize,
    /// Child frame in the parent frame at joint position 0.
    pub origin: Iso,
    /// Unit axis in the joint frame.
    pub axis: V3,
    pub(crate) dir: AxisDir,
    /// Lower position limit (rad or m); −∞ for continuous joints.
    pub lower: f64,
    /// Upper position limit (rad or m); +∞ for continuous joints.
    pub upper: f64,
    /// Maximum speed (rad/s or m/s).
    pub max_velocity: f64,
    /// Maximum acceleration (rad/s² or m/s²): the URDF's `acceleration`, or its
    /// `deceleration` when that is smaller (motion profiles are symmetric).
    pub max_accel: f64,
    /// Maximum jerk (rad/s³ or m/s³), if the URDF gives one (read whatever the URDF's
    /// version; the trapezoidal profiles do not use it yet).
    pub max_jerk: Option<f64>,
    /// Index in the robot's joint vector, for the axes on the root→tool chain.
    pub axis_index: Option<usize>,
}

impl Joint {
    /// A position of this joint in the units a programmer writes, to a tenth: degrees, or
    /// millimetres for a prismatic joint (`-165.0deg`, `250.0mm`).
    pub fn display(&self, v: f64) -> String {
        if self.kind == JointKind::Prismatic {
            format!("{}mm", crate::text::number(v * 1e3, 1))
        } else {
            format!("{}deg", crate::text::number(v.to_degrees(), 1))
        }
    }
}

/// The geometry of a collision body, in the link frame (before `origin`).
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// A box with these half extents (m).
    Box {
        /// Half extents along x, y, z.
        half: V3,
    },
    /// A cylinder along z.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Full length.
        length: f64,
    },
    /// A capsule along z (length between the two sphere centres).
    Capsule {
        /// Radius.
        radius: f64,
        /// Length of the segment.
        length: f64,
    },
    /// A sphere.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// The convex hull of a mesh's vertices (already scaled).
    Hull {
        /// Where the mesh came from.
        source: String,
        /// Vertices (m).
        points: Vec<V3>,
    },
}

/// A collision body of a link, with its parry shape built once at load time.
#[derive(Clone)]
pub struct LinkShape {
    /// What it is.
    pub geometry: Geometry,
    /// Its pose in the link frame.
    pub origin: Iso,
    /// The parry shape.
    pub shape: SharedShape,
    /// The shape's pose in the link frame as parry wants it (cylinders turned from
    /// URDF's z axis to parry's y axis).
    pub local_pose: Pose,
}

impl std::fmt::Debug for LinkShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinkShape")
            .field("geometry", &self.geometry)
            .field("origin", &self.origin)
            .finish()
    }
}

/// A rigid body of the robot.
#[derive(Clone, Debug)]
pub struct Link {
    /// Name in the URDF.
    pub name: String,
    /// The joint that attaches it to its parent (`None` for the root).
    pub parent_joint: Option<usize>,
    /// Collision bodies.
    pub shapes: Vec<LinkShape>,
}

/// A robot (or a device with axes): links in parent-before-child order, `links[0]` the root.
#[derive(Clone, Debug)]
pub struct RobotModel {
    /// The robot's name.
    pub name: String,
    /// Where it was loaded from (a file, or `builtin:NAME`).
    pub source: String,
    /// Links, parents before children.
    pub links: Vec<Link>,
    /// Joints, in the order of their child links.
    pub joints: Vec<Joint>,
    /// The joints that are the robot's axes (movable joints on the root→tool chain), in
    /// chain order; `joints[axes[i]]` is axis `i`.
    pub axes: Vec<usize>,
    /// The tool (flange) link.
    pub tool_link: usize,
    /// The analytic IK geometry, when the robot is a spherical-wrist 6-axis arm.
    pub wrist: Option<SphericalWrist>,
    /// The TCP's own speed and acceleration limits, where the model gives them.
    pub tcp: TcpLimits,
    /// The joints from the root to the tool link, in order.
    pub(crate) chain_cache: Vec<usize>,
}

/// The TCP's limits of a model (a URDF's `<tcp_limits speed="…" acceleration="…"/>`, in
/// m/s and m/s²), as a vendor's data sheet gives them: `move_l`/`move_c` never ask more
/// of the path. `None`: the axes alone bound it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TcpLimits {
    /// The fastest TCP speed (m/s).
    pub speed: Option<f64>,
    /// The largest TCP acceleration along the path (m/s²).
    pub accel: Option<f64>,
}

/// A default acceleration for joints whose model gives none: full speed in 0.3 s.
pub const DEFAULT_ACCEL_TIME: f64 = 0.3;

impl RobotModel {
    /// Number of axes.
    pub fn dof(&self) -> usize {
        self.axes.len()
    }

    /// Axis `i`'s joint.
    pub fn axis(&self, i: usize) -> &Joint {
        &self.joints[self.axes[i]]
    }

    /// Index of a link by name.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Bit i set when axis i is prismatic (a linear axis, positions in metres).
    pub fn linear_axes(&self) -> u16 {
        self.axes
            .iter()
            .enumerate()
            .filter(|(_, j)| self.joints[**j].kind == JointKind::Prismatic)
            .fold(0, |m, (i, _)| m | (1 << i))
    }

    /// Forward kinematics of every link: writes `frames[k]` = pose of link k in the root
    /// frame. `q` has one value per axis; joints off the tool chain stay at 0.
    /// `frames` must have `links.len()` entries (see [`RobotModel::frames_buffer`]).
    pub fn fk_into(&self, q: &[f64], frames: &mut [Iso]) {
        self.fk_into_from(&Iso::IDENTITY, q, frames);
    }

    /// [`RobotModel::fk_into`] with the root link placed at `base`: every frame in the
    /// cell at once, without a second pass multiplying each by the base.
    pub fn fk_into_from(&self, base: &Iso, q: &[f64], frames: &mut [Iso]) {
        frames[0] = *base;
        for j in &self.joints {
            let parent = frames[j.parent];
            let at = parent.mul(&j.origin);
            let v = j.axis_index.and_then(|i| q.get(i).copied()).unwrap_or(0.0);
            frames[j.child] = match j.kind {
                JointKind::Fixed => at,
                JointKind::Revolute | JointKind::Continuous => Iso {
                    r: mat_mul(&at.r, &j.dir.rotation(v)),
                    t: at.t,
                },
                JointKind::Prismatic => {
                    let d = j.dir.vector();
                    Iso {
                        r: at.r,
                        t: at.apply_delta(d, v),
                    }
                }
            };
        }
    }

    /// Joint `j`'s own transform at axis values `q`: the pose of its child link in its
    /// parent link (origin × the joint's motion; joints off the tool chain at 0). What a
    /// transform tree publishes per link; composing them from the root gives `fk`.
    pub fn joint_transform(&self, j: usize, q: &[f64]) -> Iso {
        let Some(joint) = self.joints.get(j) else {
            return Iso::IDENTITY;
        };
        let v = joint
            .axis_index
            .and_then(|i| q.get(i).copied())
            .unwrap_or(0.0);
        match joint.kind {
            JointKind::Fixed => joint.origin,
            JointKind::Revolute | JointKind::Continuous => Iso {
                r: mat_mul(&joint.origin.r, &joint.dir.rotation(v)),
                t: joint.origin.t,
            },
            JointKind::Prismatic => Iso {
                r: joint.origin.r,
                t: joint.origin.apply_delta(joint.dir.vector(), v),
            },
        }
    }

    /// A buffer for [`RobotModel::fk_into`].
    pub fn frames_buffer(&self) -> Vec<Iso> {
        vec![Iso::IDENTITY; self.links.len()]
    }

    /// The pose of every link (allocates; prefer [`RobotModel::fk_into`] in loops).
    pub fn fk(&self, q: &[f64]) -> Vec<Iso> {
        let mut f = self.frames_buffer();
        self.fk_into(q, &mut f);
        f
    }

    /// The pose of the tool link only, walking the chain (no other links, no allocation).
    pub fn flange(&self, q: &[f64]) -> Iso {
        let mut f = Iso::IDENTITY;
        for &j in &self.chain_cache {
            f = self.joint_step(&f, j, q);
        }
        f
    }

    pub(crate) fn joint_step(&self, parent: &Iso, j: usize, q: &[f64]) -> Iso {
        let j = &self.joints[j];
        let at = parent.mul(&j.origin);
        let v = j.axis_index.and_then(|i| q.get(i).copied()).unwrap_or(0.0);
        match j.kind {
            JointKind::Fixed => at,
            JointKind::Revolute | JointKind::Continuous => Iso {
                r: mat_mul(&at.r, &j.dir.rotation(v)),
                t: at.t,
            },
            JointKind::Prismatic => Iso {
                r: at.r,
                t: at.apply_delta(j.dir.vector(), v),
            },
        }
    }

    /// The TCP: flange × tool.
    pub fn tcp(&self, q: &[f64], tool: &Iso) -> Iso {
        self.flange(q).mul(tool)
    }

    /// Pairs of links joined by a joint: the self-collision check skips them.
    pub fn adjacent_pairs(&self) -> Vec<(usize, usize)> {
        self.joints
            .iter()
            .map(|j| (j.parent.min(j.child), j.parent.max(j.child)))
            .collect()
    }

    /// True if `q` respects every axis's position limits (with a tolerance).
    pub fn within_limits(&self, q: &[f64]) -> bool {
        q.iter().enumerate().all(|(i, v)| {
            let j = self.axis(i);
            *v >= j.lower - 1e-9 && *v <= j.upper + 1e-9
        })
    }
}

impl Iso {
    /// The translation after moving `v` along the local direction `d`.
    #[inline]
    fn apply_delta(&self, d: V3, v: f64) -> V3 {
        self.apply([d[0] * v, d[1] * v, d[2] * v])
    }

    /// As a parry pose.
    pub fn to_pose(&self) -> Pose {
        let r = &self.r;
        let m = parry3d::math::Mat3::from_cols(
            Vector::new(r[0][0], r[1][0], r[2][0]),
            Vector::new(r[0][1], r[1][1], r[2][1]),
            Vector::new(r[0][2], r[1][2], r[2][2]),
        );
        Pose::from_parts(
            Vector::new(self.t[0], self.t[1], self.t[2]),
            parry3d::math::Rot3::from_mat3(&m),
        )
    }
}

/// The geometry of a spherical-wrist arm, read from its model by
/// [`crate::ik::SphericalWrist::detect`] (kept here, with the model it belongs to).
#[derive(Clone, Debug, PartialEq)]
pub struct SphericalWrist {
    /// Root frame to axis 1's joint frame (fixed joints before it and its origin).
    pub(crate) pre: Iso,
    /// Inverse of `pre`.
    pub(crate) pre_inv: Iso,
    /// Axis 6's frame to the tool link (fixed joints after it), inverted.
    pub(crate) post_inv: Iso,
    /// Sign of each axis (+1 or −1) relative to z, y, y, x, y, x.
    pub(crate) sign: [f64; 6],
    /// Axis 2's position in axis 1's frame (x, z).
    pub(crate) shoulder: [f64; 2],
    /// Axis 2 → axis 3 (x, z).
    pub(crate) upper: [f64; 2],
    /// Axis 3 → wrist centre (x, z).
    pub(crate) fore: [f64; 2],
    /// Wrist centre → axis 6 frame, along x.
    pub(crate) hand: f64,
}
