//! The built-in arms' dynamics as docs/models.md ("Dynamics of the built-in arms") states
//! them, and the TCP limits a URDF may give.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use vworks_model::builtin;
use vworks_model::error::{ModelError, UrdfProblem};
use vworks_model::model::TcpLimits;
use vworks_model::urdf::{LoadOptions, load_str};

/// Each arm's time to full speed (the same for every axis), and its TCP limits.
#[test]
fn built_in_arms_reach_full_speed_in_the_documented_time() {
    for (name, time, tcp) in [
        ("irb120", Some(0.07), (Some(6.2), Some(28.0))),
        ("kr6r900", Some(0.1), (None, None)),
        ("lrmate200id", Some(0.1), (None, None)),
        ("ur5", None, (None, None)),
    ] {
        let m = builtin::load(name).unwrap();
        for i in 0..m.dof() {
            let j = m.axis(i);
            match time {
                Some(t) => assert!(
                    (j.max_velocity / j.max_accel - t).abs() < 1e-6,
                    "{name} axis {}: {} / {}",
                    i + 1,
                    j.max_velocity,
                    j.max_accel
                ),
                // The UR5: 10 rad/s² on every joint.
                None => assert_eq!(j.max_accel, 10.0, "{name} axis {}", i + 1),
            }
            assert_eq!(j.max_jerk, None, "{name}: no vendor publishes a jerk");
        }
        assert_eq!(
            m.tcp,
            TcpLimits {
                speed: tcp.0,
                accel: tcp.1
            },
            "{name}"
        );
    }
}

const ARM: &str = r#"<robot name="arm">
  TCP
  <link name="base"/>
  <link name="l1"/>
  <joint name="j1" type="revolute">
    <parent link="base"/>
    <child link="l1"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1"/>
  </joint>
</robot>"#;

fn load(tcp: &str) -> Result<TcpLimits, ModelError> {
    load_str(
        &ARM.replace("TCP", tcp),
        "arm.urdf",
        None,
        &LoadOptions::default(),
    )
    .map(|m| m.tcp)
}

#[test]
fn a_urdf_gives_either_tcp_limit_or_both_or_none() {
    assert_eq!(load("").unwrap(), TcpLimits::default());
    assert_eq!(
        load(r#"<tcp_limits speed="1.5"/>"#).unwrap(),
        TcpLimits {
            speed: Some(1.5),
            accel: None
        }
    );
    assert_eq!(
        load(r#"<tcp_limits acceleration='12' speed="2"/>"#).unwrap(),
        TcpLimits {
            speed: Some(2.0),
            accel: Some(12.0)
        }
    );
    // In a comment it is not there; nor is an element whose name only starts the same.
    assert_eq!(
        load(r#"<!-- <tcp_limits speed="1.5"/> -->"#).unwrap(),
        TcpLimits::default()
    );
    assert_eq!(
        load(r#"<tcp_limits_note speed="0.5"/>"#).unwrap(),
        TcpLimits::default()
    );
}

#[test]
fn tcp_limits_that_are_not_positive_numbers_are_errors_naming_the_attribute() {
    for (tcp, attribute) in [
        (r#"<tcp_limits speed="0"/>"#, "speed"),
        (r#"<tcp_limits speed="fast"/>"#, "speed"),
        (r#"<tcp_limits acceleration="-3"/>"#, "acceleration"),
        (r#"<tcp_limits acceleration="inf"/>"#, "acceleration"),
        (r#"<tcp_limits speed="1" accel="0.5"/>"#, "`accel`"),
        (
            r#"<tcp_limits speed="1"/><tcp_limits speed="0.5"/>"#,
            "twice",
        ),
    ] {
        let e = load(tcp).unwrap_err();
        let ModelError::Invalid {
            problem,
            element,
            message,
            ..
        } = &e
        else {
            panic!("{tcp}: {e}")
        };
        assert_eq!(*problem, UrdfProblem::BadDynamicLimit, "{tcp}");
        assert_eq!(element, "tcp_limits");
        assert!(message.contains(attribute), "{tcp}: {e}");
        assert!(e.to_string().starts_with("arm.urdf: tcp_limits: "), "{e}");
    }
}
