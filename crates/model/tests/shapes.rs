//! Collision shapes: built once at load, placed by forward kinematics, usable by parry.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use parry3d::query;
use vworks_model::builtin;
use vworks_model::model::Geometry;

#[test]
fn built_in_links_have_shapes_and_adjacency() {
    for name in builtin::names() {
        let m = builtin::load(name).unwrap();
        let with_shapes = m.links.iter().filter(|l| !l.shapes.is_empty()).count();
        assert!(
            with_shapes >= m.links.len() - 1,
            "{name}: {with_shapes} of {} links have shapes",
            m.links.len()
        );
        assert_eq!(m.adjacent_pairs().len(), m.joints.len());
    }
}

#[test]
fn shapes_follow_the_links_and_collide_where_they_should() {
    let m = builtin::load("irb120").unwrap();
    let shape_pose = |frames: &[vworks_model::Iso], link: usize| {
        let s = &m.links[link].shapes[0];
        (frames[link].to_pose() * s.local_pose, s.shape.clone())
    };
    let idx = |n: &str| m.link_index(n).unwrap();
    // At zero: the upper arm (link_2) and the base are apart by more than 5 cm; the
    // upper arm touches link_1 it is jointed to.
    let f = m.fk(&[0.0; 6]);
    let (p2, s2) = shape_pose(&f, idx("link_2"));
    let (pb, sb) = shape_pose(&f, idx("base_link"));
    let (p1, s1) = shape_pose(&f, idx("link_1"));
    assert!(
        query::distance(&p2, s2.as_ref(), &pb, sb.as_ref())
            .unwrap()
            .distance
            > 0.05
    );
    assert!(
        query::intersection_test(&p2, s2.as_ref(), &p1, s1.as_ref())
            .unwrap()
            .intersecting
    );
    // Fold the arm down (axis 2 +110°, axis 3 +70°): the forearm (link_4) now reaches
    // toward the base; the distance between them must shrink.
    let d0 = {
        let (p4, s4) = shape_pose(&f, idx("link_4"));
        query::distance(&p4, s4.as_ref(), &pb, sb.as_ref())
            .unwrap()
            .distance
    };
    let f = m.fk(&[0.0, 110f64.to_radians(), 70f64.to_radians(), 0.0, 0.0, 0.0]);
    let (p4, s4) = shape_pose(&f, idx("link_4"));
    let (pb, sb) = shape_pose(&f, idx("base_link"));
    let d1 = query::distance(&p4, s4.as_ref(), &pb, sb.as_ref())
        .unwrap()
        .distance;
    assert!(d1 < d0, "{d1} should be below {d0}");
}

#[test]
fn cylinders_stand_on_z_like_urdf() {
    // parry's cylinders stand on y: the loader must turn them onto z.
    let m = builtin::load("turntable").unwrap();
    let base = &m.links[0].shapes[0];
    assert!(matches!(base.geometry, Geometry::Cylinder { .. }));
    let aabb = base.shape.compute_aabb(&base.local_pose);
    let (h, r) = (aabb.maxs.z - aabb.mins.z, aabb.maxs.x - aabb.mins.x);
    assert!(
        (h - 0.4).abs() < 1e-5 && (r - 0.6).abs() < 1e-5,
        "height {h}, diameter {r}"
    );
}

#[test]
fn joint_transforms_compose_to_the_link_frames() {
    // Every link frame is its parent's frame × its joint's own transform (what the log's
    // /tf tree sends).
    for name in builtin::names() {
        let m = builtin::load(name).unwrap();
        for k in 0..50 {
            let q: Vec<f64> = (0..m.dof())
                .map(|i| {
                    let j = &m.joints[m.axes[i]];
                    let (lo, hi) = (j.lower.max(-3.0), j.upper.min(3.0));
                    lo + (hi - lo) * (((k * 7 + i * 13) % 17) as f64 / 16.0)
                })
                .collect();
            let frames = m.fk(&q);
            for (i, j) in m.joints.iter().enumerate() {
                let composed = frames[j.parent].mul(&m.joint_transform(i, &q));
                let want = frames[j.child];
                for (a, b) in composed.t.iter().zip(&want.t) {
                    assert!((a - b).abs() < 1e-12, "{name} {}", j.name);
                }
                for (a, b) in composed.r.iter().flatten().zip(want.r.iter().flatten()) {
                    assert!((a - b).abs() < 1e-12, "{name} {}", j.name);
                }
            }
        }
        assert_eq!(
            m.joint_transform(m.joints.len(), &[]),
            vworks_model::math::Iso::IDENTITY
        );
    }
}
