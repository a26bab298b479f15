//! The loader's context ([`Ctx`]): the file being read and where its files come from,
//! and the readers of values every section shares (quantities, poses, shapes, jerks), each
//! error naming the key.

use std::path::Path;

use vworks_model::RobotModel;
use vworks_model::files::Files;
use vworks_model::math::Iso;
use vworks_model::model::Geometry;
use vworks_model::text::{escape_controls, escape_controls_owned};
use vworks_vm::Dim;

use crate::cell::Body;
use crate::error::CellError;
use crate::file::{BodyFile, PoseFile};
use vworks_wslc::units::parse_quantity;

/// The largest length a workcell may give (10 km): a size or a position beyond it is a
/// typo (a unit missing), and would break the collision geometry's arithmetic.
pub(crate) const MAX_LENGTH: f64 = 1e4;

pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
    pub(crate) files: &'a dyn Files,
}

impl Ctx<'_> {
    /// The error at `key`; control characters in names the key or message quote (from
    /// the workcell) escaped as log texts are, so they cannot drive a terminal.
    pub(crate) fn bad(&self, key: &str, message: impl Into<String>) -> CellError {
        CellError::Invalid {
            file: self.file.to_string(),
            key: escape_controls(key).into_owned(),
            message: escape_controls_owned(message.into()),
        }
    }

    /// A robot's `jerk`: one value for every axis, or a list with one per axis (each
    /// an angular jerk for a revolute axis, a jerk for a prismatic one; plain numbers are
    /// SI). Replaces the URDF's `jerk` limits.
    pub(crate) fn override_jerk(
        &self,
        model: &mut RobotModel,
        v: &toml::Value,
        key: &str,
    ) -> Result<(), CellError> {
        let n = model.dof();
        let values: Vec<(&toml::Value, String)> = match v {
            toml::Value::Array(list) => {
                if list.len() != n {
                    return Err(self.bad(
                        key,
                        format!(
                            "has {} values but the robot has {n} axes; give one per axis, or one value for all",
                            list.len()
                        ),
                    ));
                }
                list.iter()
                    .enumerate()
                    .map(|(k, x)| (x, format!("{key}[{k}]")))
                    .collect()
            }
            one => (0..n).map(|_| (one, key.to_string())).collect(),
        };
        for (k, (x, at)) in values.into_iter().enumerate() {
            let dim = if (model.linear_axes() >> k) & 1 == 1 {
                Dim::JERK
            } else {
                Dim::ANGJERK
            };
            let hint: &dyn Fn() -> &'static str = &|| {
                if dim == Dim::JERK {
                    "\"5000mm/s3\" or 5 (m/s³)"
                } else {
                    "\"2000deg/s3\" or 34.9 (rad/s³)"
                }
            };
            let j = self.quantity_unchecked(x, dim, &at, hint)?;
            if !(j.is_finite() && j > 0.0) {
                return Err(self.bad(
                    &at,
                    format!(
                        "axis {} `{}`: a jerk limit must be greater than 0 and finite; write {}",
                        k + 1,
                        model.axis(k).name,
                        hint()
                    ),
                ));
            }
            let joint = model.axes[k];
            model.joints[joint].max_jerk = Some(j);
        }
        Ok(())
    }

    /// A quantity of dimension `dim`: a number (SI) or a string with a unit.
    pub(crate) fn quantity(&self, v: &toml::Value, dim: Dim, key: &str) -> Result<f64, CellError> {
        let unit_hint = || match dim {
            Dim::LENGTH => "\"250mm\" or 0.25 (metres)",
            Dim::ANGLE => "\"90deg\" or 1.5708 (radians)",
            Dim::TIME => "\"4ms\" or 0.004 (seconds)",
            Dim::SPEED => "\"250mm/s\" or 0.25 (m/s)",
            _ => "a number",
        };
        let x = self.quantity_unchecked(v, dim, key, &unit_hint)?;
        if dim == Dim::LENGTH && x.abs() > MAX_LENGTH {
            return Err(self.bad(
                key,
                format!(
                    "{x:.3e} m is out of range: lengths in a workcell are within ±10 km; write {}",
                    unit_hint()
                ),
            ));
        }
        Ok(x)
    }

    /// A quantity of dimension `dim`, finite (`nan`, `inf` and `"1e999mm"` are errors),
    /// not checked against any range.
    pub(crate) fn quantity_unchecked(
        &self,
        v: &toml::Value,
        dim: Dim,
        key: &str,
        unit_hint: &dyn Fn() -> &'static str,
    ) -> Result<f64, CellError> {
        let x = self.quantity_any(v, dim, key, unit_hint)?;
        if !x.is_finite() {
            return Err(self.bad(
                key,
                format!(
                    "{} is not a finite number; write {}",
                    match v {
                        toml::Value::String(s) => format!("`{s}`"),
                        _ => x.to_string(),
                    },
                    unit_hint()
                ),
            ));
        }
        Ok(x)
    }

    /// A quantity of dimension `dim`, NaN and infinities included.
    pub(crate) fn quantity_any(
        &self,
        v: &toml::Value,
        dim: Dim,
        key: &str,
        unit_hint: &dyn Fn() -> &'static str,
    ) -> Result<f64, CellError> {
        match v {
            toml::Value::Integer(i) => Ok(*i as f64),
            toml::Value::Float(x) => Ok(*x),
            toml::Value::String(s) => match parse_quantity(s) {
                Some(q) => q.si(dim).map_err(|d| {
                    self.bad(
                        key,
                        format!(
                            "`{s}` is {}, but {key} is {}; write {}",
                            d.described(),
                            dim.described(),
                            unit_hint()
                        ),
                    )
                }),
                None => Err(self.bad(
                    key,
                    format!("`{s}` is not a quantity; write {}", unit_hint()),
                )),
            },
            other => Err(self.bad(
                key,
                format!("expected {}, found {}", unit_hint(), other.type_str()),
            )),
        }
    }

    /// A `grip_distance` (the cell's or a robot's): a length, at least 0.
    pub(crate) fn grip_distance(&self, v: &toml::Value, key: &str) -> Result<f64, CellError> {
        let d = self.quantity(v, Dim::LENGTH, key)?;
        if d < 0.0 {
            return Err(self.bad(
                key,
                "cannot be negative: it is how far from the robot's gripper (its TCP and its tool link's collision bodies) a part can be gripped; write e.g. \"5mm\", or 0 for parts the gripper touches",
            ));
        }
        Ok(d)
    }

    pub(crate) fn pose(&self, p: Option<&PoseFile>, key: &str) -> Result<Iso, CellError> {
        let Some(p) = p else { return Ok(Iso::IDENTITY) };
        let vec3 =
            |v: &Option<Vec<toml::Value>>, dim: Dim, sub: &str| -> Result<[f64; 3], CellError> {
                let Some(v) = v else { return Ok([0.0; 3]) };
                if v.len() != 3 {
                    return Err(self.bad(
                        &format!("{key}.{sub}"),
                        format!("needs 3 values, found {}", v.len()),
                    ));
                }
                let mut out = [0.0; 3];
                for (i, x) in v.iter().enumerate() {
                    out[i] = self.quantity(x, dim, &format!("{key}.{sub}[{i}]"))?;
                }
                Ok(out)
            };
        Ok(Iso::from_xyz_rpy(
            vec3(&p.xyz, Dim::LENGTH, "xyz")?,
            vec3(&p.rpy, Dim::ANGLE, "rpy")?,
        ))
    }

    pub(crate) fn body(&self, b: &BodyFile, key: &str, dir: &Path) -> Result<Body, CellError> {
        let files = self.files;
        let given = [
            b.box_.is_some(),
            b.cylinder.is_some(),
            b.sphere.is_some(),
            b.mesh.is_some(),
        ]
        .iter()
        .filter(|x| **x)
        .count();
        if given != 1 {
            return Err(self.bad(
                key,
                format!(
                    "`{}` needs exactly one shape: box, cylinder, sphere or mesh",
                    b.name
                ),
            ));
        }
        let len = |v: &toml::Value, k: &str| -> Result<f64, CellError> {
            let x = self.quantity(v, Dim::LENGTH, k)?;
            if x > 0.0 {
                Ok(x)
            } else {
                Err(self.bad(k, "must be greater than zero"))
            }
        };
        let geometry = if let Some(bx) = &b.box_ {
            if bx.len() != 3 {
                return Err(self.bad(&format!("{key}.box"), "needs 3 sizes: [x, y, z]"));
            }
            let mut half = [0.0; 3];
            for (i, v) in bx.iter().enumerate() {
                half[i] = len(v, &format!("{key}.box[{i}]"))? / 2.0;
            }
            Geometry::Box { half }
        } else if let Some(c) = &b.cylinder {
            if c.len() != 2 {
                return Err(self.bad(&format!("{key}.cylinder"), "needs [radius, length]"));
            }
            Geometry::Cylinder {
                radius: len(&c[0], &format!("{key}.cylinder[0]"))?,
                length: len(&c[1], &format!("{key}.cylinder[1]"))?,
            }
        } else if let Some(r) = &b.sphere {
            Geometry::Sphere {
                radius: len(r, &format!("{key}.sphere"))?,
            }
        } else {
            let mesh = b.mesh.as_deref().unwrap_or_default();
            let path = dir.join(mesh);
            let bytes = files.read(&path).map_err(|e| {
                self.bad(
                    &format!("{key}.mesh"),
                    format!("cannot read `{}`: {e}{}", path.display(), read_hint(&e)),
                )
            })?;
            let s = b.scale.unwrap_or(1.0);
            if !(s.is_finite() && s > 0.0 && s <= MAX_LENGTH) {
                return Err(self.bad(
                    &format!("{key}.scale"),
                    format!("{s} is not a usable scale; give a number greater than 0 (1 keeps the mesh's size)"),
                ));
            }
            let points = vworks_model::mesh::read_vertices(&bytes, mesh, [s; 3]).map_err(|e| {
                self.bad(&format!("{key}.mesh"), format!("`{}`: {e}", path.display()))
            })?;
            Geometry::Hull {
                source: path.display().to_string(),
                points,
            }
        };
        let shaped = vworks_model::urdf::build_shape(geometry, Iso::IDENTITY, self.file, key)
            .map_err(|e| self.bad(key, e.to_string()))?;
        let local = match shaped.geometry {
            Geometry::Cylinder { .. } => {
                Iso::from_xyz_rpy([0.0; 3], [std::f64::consts::FRAC_PI_2, 0.0, 0.0])
            }
            _ => Iso::IDENTITY,
        };
        Ok(Body {
            name: b.name.clone(),
            geometry: shaped.geometry,
            shape: shaped.shape,
            local,
            pose: self.pose(b.pose.as_ref(), &format!("{key}.pose"))?,
        })
    }
}

/// What to do about a file that cannot be read.
pub(crate) fn read_hint(e: &std::io::Error) -> &'static str {
    match e.kind() {
        std::io::ErrorKind::NotFound => {
            "; check the path: it is relative to the workcell file's folder"
        }
        std::io::ErrorKind::PermissionDenied => "; check the file's permissions",
        _ => "",
    }
}
