//! Value types of WSL and their physical dimensions.
//!
//! Every `num` carries a [`Dim`]: integer exponents of length, angle and time. Units only
//! exist in source text; values are stored in SI (metre, radian, second), so `250mm/s` is the
//! `num` 0.25 with dimension length·time⁻¹. A ratio such as `50%` is a plain number (0.5).
//!
//! At run time a value occupies a fixed number of 64-bit *slots* ([`Type::width`]): scalars
//! one, a pose six (x, y, z in m; rx, ry, rz in rad), a joint vector [`MAX_AXES`].

use std::fmt;

/// The most axes a robot (and so a `joints` value) may have.
pub const MAX_AXES: usize = 12;

/// Slots taken by a `pose` value: x, y, z (m), rx, ry, rz (rad).
pub const POSE_WIDTH: u8 = 6;

/// A physical dimension: exponents of length, angle and time.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug, Default, PartialOrd, Ord)]
pub struct Dim {
    /// Exponent of length (metre).
    pub length: i8,
    /// Exponent of angle (radian).
    pub angle: i8,
    /// Exponent of time (second).
    pub time: i8,
}

impl Dim {
    /// A plain (dimensionless) number, ratios included.
    pub const PLAIN: Dim = Dim::new(0, 0, 0);
    /// Length (m).
    pub const LENGTH: Dim = Dim::new(1, 0, 0);
    /// Angle (rad).
    pub const ANGLE: Dim = Dim::new(0, 1, 0);
    /// Time (s).
    pub const TIME: Dim = Dim::new(0, 0, 1);
    /// Linear speed (m/s).
    pub const SPEED: Dim = Dim::new(1, 0, -1);
    /// Angular speed (rad/s).
    pub const ANGSPEED: Dim = Dim::new(0, 1, -1);
    /// Linear acceleration (m/s²).
    pub const ACCEL: Dim = Dim::new(1, 0, -2);
    /// Angular acceleration (rad/s²).
    pub const ANGACCEL: Dim = Dim::new(0, 1, -2);
    /// Linear jerk (m/s³).
    pub const JERK: Dim = Dim::new(1, 0, -3);
    /// Angular jerk (rad/s³).
    pub const ANGJERK: Dim = Dim::new(0, 1, -3);

    /// A dimension from its exponents.
    pub const fn new(length: i8, angle: i8, time: i8) -> Dim {
        Dim {
            length,
            angle,
            time,
        }
    }

    /// The dimension of a product, or `None` if an exponent overflows.
    pub fn times(self, o: Dim) -> Option<Dim> {
        Some(Dim::new(
            self.length.checked_add(o.length)?,
            self.angle.checked_add(o.angle)?,
            self.time.checked_add(o.time)?,
        ))
    }

    /// The dimension of a quotient, or `None` if an exponent overflows.
    pub fn per(self, o: Dim) -> Option<Dim> {
        Some(Dim::new(
            self.length.checked_sub(o.length)?,
            self.angle.checked_sub(o.angle)?,
            self.time.checked_sub(o.time)?,
        ))
    }

    /// The dimension of a square root, or `None` if an exponent is odd.
    pub fn sqrt(self) -> Option<Dim> {
        if self.length % 2 != 0 || self.angle % 2 != 0 || self.time % 2 != 0 {
            return None;
        }
        Some(Dim::new(self.length / 2, self.angle / 2, self.time / 2))
    }

    /// True for a plain number.
    pub fn is_plain(self) -> bool {
        self == Dim::PLAIN
    }

    /// A short name: `length`, `speed`, … or a formula such as `length^2/time`.
    pub fn name(self) -> String {
        match self {
            Dim::PLAIN => "plain number".into(),
            Dim::LENGTH => "length".into(),
            Dim::ANGLE => "angle".into(),
            Dim::TIME => "time".into(),
            Dim::SPEED => "speed".into(),
            Dim::ANGSPEED => "angular speed".into(),
            Dim::ACCEL => "acceleration".into(),
            Dim::ANGACCEL => "angular acceleration".into(),
            Dim::JERK => "jerk".into(),
            Dim::ANGJERK => "angular jerk".into(),
            _ => self.formula(),
        }
    }

    /// The dimension as a formula of base dimensions, e.g. `length^2/time`.
    pub fn formula(self) -> String {
        let mut num = Vec::new();
        let mut den = Vec::new();
        for (name, e) in [
            ("length", self.length),
            ("angle", self.angle),
            ("time", self.time),
        ] {
            let part = |e: i8| {
                if e.unsigned_abs() == 1 {
                    name.to_string()
                } else {
                    format!("{name}^{}", e.unsigned_abs())
                }
            };
            if e > 0 {
                num.push(part(e));
            } else if e < 0 {
                den.push(part(e));
            }
        }
        let num = if num.is_empty() {
            "1".to_string()
        } else {
            num.join("*")
        };
        if den.is_empty() {
            num
        } else {
            format!("{num}/{}", den.join("/"))
        }
    }

    /// The unit a value of this dimension is written in by `log` and the disassembler,
    /// with the factor from SI: `(unit, si_per_unit)`. Lengths print in mm, angles in deg.
    pub fn display_unit(self) -> (String, f64) {
        let mut factor = 1.0;
        let mut num = Vec::new();
        let mut den = Vec::new();
        for (unit, e, f) in [
            ("mm", self.length, 1e-3),
            ("deg", self.angle, std::f64::consts::PI / 180.0),
            ("s", self.time, 1.0),
        ] {
            factor *= f64::powi(f, i32::from(e));
            let text = if e.unsigned_abs() == 1 {
                unit.to_string()
            } else {
                format!("{unit}{}", e.unsigned_abs())
            };
            if e > 0 {
                num.push(text);
            } else if e < 0 {
                den.push(text);
            }
        }
        let mut s = num.join("*");
        if !den.is_empty() {
            if s.is_empty() {
                s.push('1');
            }
            s.push('/');
            s.push_str(&den.join("/"));
        }
        (s, factor)
    }

    /// The article-prefixed name used in messages: "a length", "an angle", "a plain number".
    pub fn described(self) -> String {
        let n = self.name();
        let article = if n.starts_with(['a', 'e', 'i', 'o', 'u']) {
            "an"
        } else {
            "a"
        };
        format!("{article} {n}")
    }
}

impl fmt::Display for Dim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// The type of a run-time value.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug, PartialOrd, Ord)]
pub enum Type {
    /// `true` or `false`.
    Bool,
    /// A 64-bit signed integer.
    Int,
    /// A 64-bit float with a dimension, stored in SI units.
    Num(Dim),
    /// One value per robot axis (rad for revolute, m for prismatic axes).
    Joints,
    /// Position (m) and fixed-axis roll-pitch-yaw orientation (rad).
    Pose,
    /// A text (RAPID's `string`; WSL writes text only in `log` and `fail`): one slot, a
    /// handle of the robot's texts ([`crate::texts::Texts`]): 0 is the empty text, `k + 1`
    /// the module's string `k`, and the handles after those the texts the run made. A text
    /// is its robot's own: it is never a global, and never crosses to another robot.
    Text,
}

impl Type {
    /// How many 64-bit slots a value of this type takes on the stack or in a frame.
    pub fn width(self) -> u8 {
        match self {
            Type::Bool | Type::Int | Type::Num(_) | Type::Text => 1,
            Type::Pose => POSE_WIDTH,
            Type::Joints => MAX_AXES as u8,
        }
    }

    /// True for `bool`, `int` and `num` — the types a `global` may have.
    pub fn is_scalar(self) -> bool {
        matches!(self, Type::Bool | Type::Int | Type::Num(_))
    }

    /// The WSL spelling: `bool`, `int`, `length`, `num`, `num(length^2)`, `joints`, `pose`.
    pub fn name(self) -> String {
        match self {
            Type::Bool => "bool".into(),
            Type::Int => "int".into(),
            Type::Num(Dim::PLAIN) => "num".into(),
            Type::Num(Dim::LENGTH) => "length".into(),
            Type::Num(Dim::ANGLE) => "angle".into(),
            Type::Num(Dim::TIME) => "time".into(),
            Type::Num(Dim::SPEED) => "speed".into(),
            Type::Num(Dim::ANGSPEED) => "angspeed".into(),
            Type::Num(d) => format!("num({})", d.formula()),
            Type::Joints => "joints".into(),
            Type::Pose => "pose".into(),
            Type::Text => "text".into(),
        }
    }
}

impl fmt::Display for Type {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// A value known before the run: constants, initial values of globals and module variables.
#[derive(Clone, PartialEq, Debug)]
pub enum ConstValue {
    /// A `bool`.
    Bool(bool),
    /// An `int`.
    Int(i64),
    /// A `num` in SI units; its dimension is in the accompanying [`Type`].
    Num(f64),
    /// A joint vector (rad or m per axis), at most [`MAX_AXES`] values.
    Joints(Vec<f64>),
    /// A pose: x, y, z (m), rx, ry, rz (rad).
    Pose([f64; 6]),
    /// A text: the index of the module's string (its slot is the handle `index + 1`).
    Text(u32),
}

impl ConstValue {
    /// The zero value of a type: `false`, `0`, `0.0`, all-zero joints, the identity pose.
    pub fn zero(ty: Type) -> ConstValue {
        match ty {
            Type::Bool => ConstValue::Bool(false),
            Type::Int => ConstValue::Int(0),
            Type::Num(_) => ConstValue::Num(0.0),
            Type::Joints => ConstValue::Joints(Vec::new()),
            Type::Pose => ConstValue::Pose([0.0; 6]),
            Type::Text => ConstValue::Text(u32::MAX),
        }
    }

    /// True when this value can be a value of `ty`.
    pub fn fits(&self, ty: Type) -> bool {
        match (self, ty) {
            (ConstValue::Bool(_), Type::Bool)
            | (ConstValue::Int(_), Type::Int)
            | (ConstValue::Num(_), Type::Num(_))
            | (ConstValue::Pose(_), Type::Pose)
            | (ConstValue::Text(_), Type::Text) => true,
            (ConstValue::Joints(v), Type::Joints) => v.len() <= MAX_AXES,
            _ => false,
        }
    }

    /// True when every number in the value is finite (no NaN or infinity).
    pub fn is_finite(&self) -> bool {
        match self {
            ConstValue::Bool(_) | ConstValue::Int(_) | ConstValue::Text(_) => true,
            ConstValue::Num(x) => x.is_finite(),
            ConstValue::Joints(v) => v.iter().all(|x| x.is_finite()),
            ConstValue::Pose(p) => p.iter().all(|x| x.is_finite()),
        }
    }

    /// Writes the value into run-time slots (`out.len()` must be the type's width).
    /// Joint vectors are zero-padded to [`MAX_AXES`].
    pub fn write_slots(&self, out: &mut [u64]) {
        out.iter_mut().for_each(|s| *s = 0);
        match self {
            ConstValue::Bool(b) => out[0] = u64::from(*b),
            ConstValue::Int(i) => out[0] = *i as u64,
            ConstValue::Num(x) => out[0] = x.to_bits(),
            ConstValue::Joints(v) => {
                for (s, x) in out.iter_mut().zip(v) {
                    *s = x.to_bits();
                }
            }
            ConstValue::Pose(p) => {
                for (s, x) in out.iter_mut().zip(p) {
                    *s = x.to_bits();
                }
            }
            // The empty text (the zero value) is handle 0.
            ConstValue::Text(u32::MAX) => out[0] = 0,
            ConstValue::Text(k) => out[0] = u64::from(*k) + 1,
        }
    }

    /// Formats the value as WSL source would write it, in display units for `ty`.
    pub fn display(&self, ty: Type) -> String {
        match (self, ty) {
            (ConstValue::Bool(b), _) => b.to_string(),
            (ConstValue::Int(i), _) => i.to_string(),
            (ConstValue::Num(x), Type::Num(d)) => fmt_quantity(*x, d),
            (ConstValue::Num(x), _) => fmt_num(*x),
            (ConstValue::Joints(v), _) => {
                let parts: Vec<String> = v.iter().map(|x| fmt_quantity(*x, Dim::ANGLE)).collect();
                format!("joints({})", parts.join(", "))
            }
            (ConstValue::Pose(p), _) => {
                let parts: Vec<String> = p
                    .iter()
                    .enumerate()
                    .map(|(i, x)| fmt_quantity(*x, if i < 3 { Dim::LENGTH } else { Dim::ANGLE }))
                    .collect();
                format!("pose({})", parts.join(", "))
            }
            (ConstValue::Text(u32::MAX), _) => "\"\"".into(),
            (ConstValue::Text(k), _) => format!("text#{k}"),
        }
    }
}

/// Formats a float with up to 9 significant decimals and no trailing zeros.
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if x == x.trunc() && x.abs() < 1e15 {
        return format!("{x:.1}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string();
    }
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// Formats an SI value in the display unit of its dimension: `0.25` length → `250mm`.
pub fn fmt_quantity(si: f64, dim: Dim) -> String {
    let (unit, factor) = dim.display_unit();
    format!("{}{}", fmt_num(si / factor), unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimension_algebra() {
        assert_eq!(Dim::LENGTH.per(Dim::TIME), Some(Dim::SPEED));
        assert_eq!(Dim::SPEED.per(Dim::TIME), Some(Dim::ACCEL));
        assert_eq!(
            Dim::LENGTH.times(Dim::LENGTH).and_then(Dim::sqrt),
            Some(Dim::LENGTH)
        );
        assert_eq!(Dim::LENGTH.sqrt(), None);
        assert_eq!(Dim::new(2, 0, -1).formula(), "length^2/time");
        assert_eq!(Dim::TIME.described(), "a time");
        assert_eq!(Dim::ANGLE.described(), "an angle");
    }

    #[test]
    fn quantities_print_in_display_units() {
        assert_eq!(fmt_quantity(0.25, Dim::SPEED), "250mm/s");
        assert_eq!(
            fmt_quantity(std::f64::consts::FRAC_PI_2, Dim::ANGLE),
            "90deg"
        );
        assert_eq!(fmt_quantity(2.0, Dim::TIME), "2s");
        assert_eq!(fmt_quantity(0.5, Dim::PLAIN), "0.5");
        assert_eq!(fmt_num(-0.0), "0");
    }
}
