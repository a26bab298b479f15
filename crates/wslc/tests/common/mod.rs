//! Helpers shared by the integration tests.

use vworks_wslc::{Sources, compile, render};

/// Compiles `src`, or fails the test with the rendered diagnostics and the source.
pub fn must_compile(path: &str, src: &str) -> vworks_vm::Module {
    match compile(path, src) {
        Ok(out) => out.module,
        Err(e) => {
            let mut s = Sources::new();
            s.add(path, src);
            panic!(
                "{path} does not compile:\n{}\n--- source ---\n{src}",
                render(&e.diagnostics, &s, false)
            );
        }
    }
}
