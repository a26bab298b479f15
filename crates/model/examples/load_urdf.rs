//! Loads a URDF and prints its axes, or the error: `cargo run -p vworks-model --example
//! load_urdf -- FILE [TOOL_LINK]`.

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(file) = args.next() else {
        eprintln!("usage: load_urdf FILE [TOOL_LINK]");
        std::process::exit(2);
    };
    let opts = vworks_model::urdf::LoadOptions {
        tool_link: args.next(),
        package_paths: vec![],
    };
    match vworks_model::urdf::load_file(std::path::Path::new(&file), &opts) {
        Ok(m) => {
            println!(
                "{}: {} links, {} axes, tool link {}",
                m.name,
                m.links.len(),
                m.dof(),
                m.links[m.tool_link].name
            );
            for i in 0..m.dof() {
                let j = m.axis(i);
                println!(
                    "  axis {} {:<24} {:?} [{:.4}, {:.4}] vmax {:.3} amax {:.3}",
                    i + 1,
                    j.name,
                    j.kind,
                    j.lower,
                    j.upper,
                    j.max_velocity,
                    j.max_accel
                );
            }
            println!(
                "  analytic IK: {}",
                if m.wrist.is_some() {
                    "yes"
                } else {
                    "no (numeric)"
                }
            );
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
