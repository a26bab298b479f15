//! The narrow phase: the gap between two placed shapes — capsules and balls exactly in
//! closed form (f64), other shapes by parry3d-f64 — and the small vector helpers it needs.

use parry3d::math::Pose;

/// The gap between two placed shapes (m; negative: the depth they overlap by) and the
/// point of each nearest the other, if the gap is at most `within` (a bounded query: parry
/// stops early when the shapes are farther apart).
///
/// Capsules and balls (most links of the built-in robots) are measured here from their
/// axis segments ([`capsule_gap`]): exact, and faster than GJK. Other shapes go to parry's
/// bounded `closest_points`, and when they intersect to its `contact` for the depth and
/// points (its `contact` alone missed touching cylinders: "no contact" at a boundary where
/// they overlapped; without a depth the contact is reported at depth 0 and the shapes'
/// origins).
///
/// parry is the f64 build (`parry3d-f64`): in f32, its GJK's relative tolerance made
/// gaps of curved shapes mm too large (up to 11.5 mm on random capsules 0.1–0.6 m apart),
/// read nearly parallel capsules overlapping by µm as 1 µm apart or not in contact, and
/// called a capsule 1.9 mm from a cylinder intersecting; the sweep then missed or invented
/// first contacts by milliseconds. In f64 the same queries agree with brute force to the
/// sampling's resolution (14 µm at 0.6 m apart, 5e-8 m within 1 cm).
pub(super) fn gap(
    pa: &Pose,
    a: &dyn parry3d::shape::Shape,
    pb: &Pose,
    b: &dyn parry3d::shape::Shape,
    within: f64,
) -> Option<(f64, V3, V3)> {
    if let (Some(ca), Some(cb)) = (Capsule::of(a), Capsule::of(b)) {
        let found = capsule_gap(pa, &ca, pb, &cb);
        return (found.0 <= within).then_some(found);
    }
    use parry3d::query::ClosestPoints;
    let v = |p: parry3d::math::Vector| [p.x, p.y, p.z];
    match parry3d::query::closest_points(pa, a, pb, b, within.max(0.0)) {
        Ok(ClosestPoints::WithinMargin(p1, p2)) => Some(((p2 - p1).length(), v(p1), v(p2))),
        Ok(ClosestPoints::Intersecting) => Some(match parry3d::query::contact(pa, a, pb, b, 0.0) {
            Ok(Some(c)) => (c.dist.min(0.0), v(c.point1), v(c.point2)),
            _ => (0.0, v(pa.translation), v(pb.translation)),
        }),
        _ => None,
    }
}

/// The distance between two placed shapes (m; 0 when they overlap), unbounded: how far
/// a part is from a gripper, and the tests' reference for the closed forms.
pub(super) fn distance(
    pa: &Pose,
    a: &dyn parry3d::shape::Shape,
    pb: &Pose,
    b: &dyn parry3d::shape::Shape,
) -> f64 {
    if let (Some(ca), Some(cb)) = (Capsule::of(a), Capsule::of(b)) {
        return capsule_gap(pa, &ca, pb, &cb).0.max(0.0);
    }
    parry3d::query::distance(pa, a, pb, b).map_or(0.0, |d| d.distance)
}

/// How much of a gap parry measured is relied on when skipping time (all of it for
/// capsules and balls, measured exactly here). GJK stops within a relative tolerance of
/// about 5e-8 in f64; 0.1 % leaves a wide margin, so a gap slightly too large never steps
/// over a contact.
pub(super) fn trust(a: &dyn parry3d::shape::Shape, b: &dyn parry3d::shape::Shape) -> f64 {
    if Capsule::of(a).is_some() && Capsule::of(b).is_some() {
        1.0
    } else {
        0.999
    }
}

pub(super) use vworks_model::math::{V3, axpy, cross, dot, sub};

/// Point `p` (in the shape's frame) placed by `pose`, in f64.
pub(super) fn place(pose: &Pose, p: parry3d::math::Vector) -> V3 {
    let q = pose.rotation;
    let (u, w) = ([q.x, q.y, q.z], q.w);
    let v = [p.x, p.y, p.z];
    // v + 2w (u × v) + 2 u × (u × v), for a unit quaternion (u, w).
    let t = cross(u, v);
    let t = [2.0 * t[0], 2.0 * t[1], 2.0 * t[2]];
    let (r, ut) = (axpy(w, t, v), cross(u, t));
    let r = [r[0] + ut[0], r[1] + ut[1], r[2] + ut[2]];
    let o = pose.translation;
    [r[0] + o.x, r[1] + o.y, r[2] + o.z]
}

/// A capsule, or a ball as a capsule of zero length: its axis segment and radius.
pub(super) struct Capsule {
    pub(super) a: parry3d::math::Vector,
    pub(super) b: parry3d::math::Vector,
    pub(super) radius: f64,
}

impl Capsule {
    pub(super) fn of(shape: &dyn parry3d::shape::Shape) -> Option<Capsule> {
        if let Some(c) = shape.as_capsule() {
            return Some(Capsule {
                a: c.segment.a,
                b: c.segment.b,
                radius: c.radius,
            });
        }
        shape.as_ball().map(|ball| Capsule {
            a: parry3d::math::Vector::ZERO,
            b: parry3d::math::Vector::ZERO,
            radius: ball.radius,
        })
    }
}

/// The gap between two placed capsules and the point of each nearest the other:
/// the closest points of their axis segments (Ericson, *Real-Time Collision Detection*,
/// 5.1.9, which handles parallel and degenerate segments), less both radii.
pub(super) fn capsule_gap(pa: &Pose, ca: &Capsule, pb: &Pose, cb: &Capsule) -> (f64, V3, V3) {
    const EPS: f64 = 1e-18;
    let (p1, q1) = (place(pa, ca.a), place(pa, ca.b));
    let (p2, q2) = (place(pb, cb.a), place(pb, cb.b));
    let (d1, d2, r) = (sub(q1, p1), sub(q2, p2), sub(p1, p2));
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let (s, t) = if a <= EPS && e <= EPS {
        (0.0, 0.0)
    } else if a <= EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = dot(d1, r);
        if e <= EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = dot(d1, d2);
            let denom = a * e - b * b;
            // Parallel segments: any s works; take 0 and let t choose.
            let s = if denom > EPS * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    let (c1, c2) = (axpy(s, d1, p1), axpy(t, d2, p2));
    let between = sub(c2, c1);
    let len = dot(between, between).sqrt();
    let (ra, rb) = (ca.radius, cb.radius);
    // The points on the surfaces, each towards the other axis (the axis points when the
    // axes meet).
    let (p1, p2) = if len > 0.0 {
        (axpy(ra / len, between, c1), axpy(-rb / len, between, c2))
    } else {
        (c1, c2)
    };
    (len - ra - rb, p1, p2)
}
