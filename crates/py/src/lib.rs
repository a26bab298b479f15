//! Python bindings of vworks (`import vworks`), built with maturin.
//!
//! Not built yet: issue 7 adds the pyo3 module (compile, load a cell, run or step it,
//! read robot state, events and logs). The crate holds its place in the workspace and is
//! outside `default-members`, because building it needs a Python environment.
