//! What the VM's property tests of zones and jerks share: one VM running a program on an
//! IRB 120 at the tests' home, its axes jerk-limited if asked.

#![allow(clippy::unwrap_used)] // tests fail by panicking

use std::sync::Arc;

use vworks_model::builtin;
use vworks_vm::machine::{Vm, VmConfig};

/// The tests' home: the joints every VM starts at, for a program's first `move_j`.
pub const HOME: &str = "joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg)";

/// A VM running `src` on an IRB 120 at [`HOME`]; with `ramp`, jerk limits that ramp each
/// axis's acceleration up in `ramp` seconds (jerk = acceleration / ramp).
pub fn irb120_vm(src: &str, ramp: Option<f64>) -> Vm {
    let out = vworks_wslc::compile("t.wsl", src).unwrap_or_else(|e| panic!("{e}\n{src}"));
    let m = Arc::new(out.module);
    let entry = m.proc_index("main").unwrap();
    let mut model = builtin::load("irb120").unwrap();
    if let Some(ramp) = ramp {
        for k in 0..model.dof() {
            let j = model.axes[k];
            model.joints[j].max_jerk = Some(model.joints[j].max_accel / ramp);
        }
    }
    let cfg = VmConfig {
        start_joints: vec![
            0.0,
            -30f64.to_radians(),
            30f64.to_radians(),
            0.0,
            60f64.to_radians(),
            0.0,
        ],
        ..VmConfig::default()
    };
    Vm::new(m, Arc::new(model), cfg, Some(entry))
}
