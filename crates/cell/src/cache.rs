//! Programs and models by what they are made from, shared by a workcell's variants: each
//! program compiled and each model loaded once.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, PoisonError};

use vworks_model::RobotModel;
use vworks_vm::Module;
use vworks_wslc::Diagnostic;
use vworks_wslc::rapid::IoSignal;

/// A program compiled for the cache: its source files (path, text) and the module with
/// its warnings, or its diagnostics.
pub(crate) struct Compiled {
    pub(crate) sources: Vec<(String, String)>,
    pub(crate) result: Result<(Arc<Module>, Vec<Diagnostic>), Vec<Diagnostic>>,
}

/// A loaded model and the URDF file (path, bytes) it came from, if it did.
pub(crate) type CachedModel = (Arc<RobotModel>, Option<(String, Vec<u8>)>);

/// What a robot's program is compiled from: its files (paths as the loader reads them, in
/// order) and, for a RAPID program, the robot's wired I/O signals (robots that share a
/// file but not their signals get a module each).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct ProgramKey {
    pub(crate) files: Vec<String>,
    pub(crate) signals: Option<Vec<IoSignal>>,
}

/// What a robot's model is loaded from: the workcell's keys that make it.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct ModelKey {
    pub(crate) model: Option<String>,
    pub(crate) urdf: Option<String>,
    pub(crate) tool_link: Option<String>,
    pub(crate) package_path: Vec<String>,
    /// The `jerk` value as TOML writes it (a TOML value has no order of its own).
    pub(crate) jerk: Option<String>,
    /// The `tcp_speed` and `tcp_acceleration` values, as TOML writes them.
    pub(crate) tcp: [Option<String>; 2],
}

/// Programs and models by what they are made from, shared by the variants.
#[derive(Default)]
pub(crate) struct Cache {
    programs: Mutex<BTreeMap<ProgramKey, Arc<Compiled>>>,
    models: Mutex<BTreeMap<ModelKey, CachedModel>>,
}

impl Cache {
    pub(crate) fn program(&self, key: &ProgramKey) -> Option<Arc<Compiled>> {
        let p = self.programs.lock().unwrap_or_else(PoisonError::into_inner);
        p.get(key).cloned()
    }

    pub(crate) fn keep_program(&self, key: &ProgramKey, c: Compiled) -> Arc<Compiled> {
        let c = Arc::new(c);
        let mut p = self.programs.lock().unwrap_or_else(PoisonError::into_inner);
        p.insert(key.clone(), Arc::clone(&c));
        c
    }

    /// A model and its URDF file (path, bytes) if it came from one.
    pub(crate) fn model(&self, key: &ModelKey) -> Option<CachedModel> {
        let m = self.models.lock().unwrap_or_else(PoisonError::into_inner);
        m.get(key).cloned()
    }

    pub(crate) fn keep_model(
        &self,
        key: ModelKey,
        model: Arc<RobotModel>,
        urdf: Option<(String, Vec<u8>)>,
    ) -> Arc<RobotModel> {
        let mut m = self.models.lock().unwrap_or_else(PoisonError::into_inner);
        m.insert(key, (Arc::clone(&model), urdf));
        model
    }
}
