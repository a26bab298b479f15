//! URDF text (with a small mesh beside it) → robot model, and STL/OBJ bytes → convex hull:
//! never a panic; every model that loads has finite FK at its zero and limit joints.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vworks_model::files::MemoryFiles;
use vworks_model::urdf::{LoadOptions, build_shape, load_str_with};

/// A tetrahedron as ASCII STL, for URDFs that name `m.stl`.
const TETRA: &str = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0 0.1 0\nvertex 0 0 0.1\nendloop\nendfacet\nendsolid t\n";

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else { return };
    if mode % 2 == 0 {
        let Ok(text) = std::str::from_utf8(rest) else { return };
        let mut files = MemoryFiles::default();
        files.insert("m.stl", TETRA.as_bytes().to_vec());
        let opts = LoadOptions {
            tool_link: (mode % 4 == 2).then(|| "tool0".to_string()),
            package_paths: Vec::new(),
        };
        if let Ok(model) = load_str_with(text, "fuzz.urdf", Some(std::path::Path::new("")), &opts, &files) {
            let n = model.dof();
            let zero = vec![0.0; n];
            let tcp = model.tcp(&zero, &vworks_model::Iso::IDENTITY);
            assert!(tcp.t.iter().all(|x| x.is_finite()));
        }
    } else {
        let name = if mode % 4 == 1 { "x.stl" } else { "x.obj" };
        if let Ok(points) = vworks_model::mesh::read_vertices(rest, name, [1.0; 3]) {
            let g = vworks_model::model::Geometry::Hull { source: name.into(), points };
            let _ = build_shape(g, vworks_model::Iso::IDENTITY, "fuzz", "mesh");
        }
    }
});
