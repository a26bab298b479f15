//! FK → IK → FK on 10,000 random reachable poses per model: at least 99.9 % solved, each
//! to within 1e-6 m and 1e-6 rad. Analytic IK (spherical-wrist arms) starts from the
//! zero joints; numeric IK from a fixed home, as a robot's current joints would be.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use vworks_model::builtin;
use vworks_model::ik::pose_error;

struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn round_trip(name: &str, n: usize) -> (usize, f64, f64) {
    let m = builtin::load(name).unwrap();
    let dof = m.dof();
    let mut rng = Rng(0x1234_5678_9abc_def1 ^ name.len() as u64);
    let home = vec![0.0; dof];
    let mut q = vec![0.0; dof];
    let mut truth = vec![0.0; dof];
    let (mut solved, mut worst_p, mut worst_r) = (0, 0.0f64, 0.0f64);
    for _ in 0..n {
        for (i, t) in truth.iter_mut().enumerate() {
            let j = m.axis(i);
            let (lo, hi) = (
                j.lower.max(-2.0 * std::f64::consts::PI),
                j.upper.min(2.0 * std::f64::consts::PI),
            );
            *t = lo + rng.unit() * (hi - lo);
        }
        let target = m.flange(&truth);
        if m.ik(&target, &home, &mut q).is_ok() {
            let (dp, dr) = pose_error(&m.flange(&q), &target);
            assert!(m.within_limits(&q), "{name}: solution outside limits {q:?}");
            if dp < 1e-6 && dr < 1e-6 {
                solved += 1;
            }
            worst_p = worst_p.max(dp);
            worst_r = worst_r.max(dr);
        }
    }
    (solved, worst_p, worst_r)
}

#[test]
fn ik_round_trips_on_10000_poses_per_model() {
    const N: usize = 10_000;
    for name in builtin::names() {
        let (solved, wp, wr) = round_trip(name, N);
        let rate = solved as f64 / N as f64;
        eprintln!(
            "{name}: {solved}/{N} solved ({:.2} %), worst error {wp:.1e} m {wr:.1e} rad",
            rate * 100.0
        );
        assert!(rate >= 0.999, "{name}: only {solved} of {N} solved");
    }
}

#[test]
fn each_ik_failure_names_the_pose_and_why() {
    use vworks_model::IkError;
    let irb = builtin::load("irb120").unwrap();
    let ur5 = builtin::load("ur5").unwrap();
    let mut q = [0.0; 6];
    // Out of reach (analytic).
    let mut far = irb.flange(&[0.0; 6]);
    far.t = [2.5, 0.0, 0.3];
    let e = irb.ik(&far, &[0.0; 6], &mut q).unwrap_err();
    assert!(matches!(e, IkError::OutOfReach { .. }), "{e}");
    assert!(
        e.to_string().contains("x 2.5000 m") && e.to_string().contains("out of reach"),
        "{e}"
    );
    // Reachable only outside the limits: axis 3 at 100° (its limit is +70°) puts the
    // wrist where no in-limit configuration reaches; search a few such poses.
    let mut rng = Rng(99);
    let mut found = None;
    for _ in 0..200 {
        let truth = [
            rng.unit() - 0.5,
            rng.unit() - 0.5,
            100f64.to_radians(),
            rng.unit() - 0.5,
            0.5 + rng.unit(),
            rng.unit(),
        ];
        if let Err(e @ IkError::JointLimits { .. }) = irb.ik(&irb.flange(&truth), &[0.0; 6], &mut q)
        {
            found = Some(e);
            break;
        }
    }
    let e = found.expect("some pose is reachable only outside the limits");
    assert!(
        e.to_string().contains("outside its joint limits") && e.to_string().contains("limits"),
        "{e}"
    );
    // Numeric: no convergence, with the remaining error.
    let mut far = ur5.flange(&[0.0; 6]);
    far.t = [3.0, 0.0, 0.0];
    let e = ur5.ik(&far, &[0.0; 6], &mut q).unwrap_err();
    assert!(matches!(e, IkError::NoConvergence { .. }), "{e}");
    assert!(
        e.to_string().contains("x 3.0000 m") && e.to_string().contains("singularity"),
        "{e}"
    );
}
