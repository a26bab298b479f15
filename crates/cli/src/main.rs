//! `vworks`, the command-line front end.
//!
//! - `vworks check FILE…`: compile each program and print every diagnostic; exit 1 on any
//!   error.
//! - `vworks build FILE [-o OUT.wslb]`: compile one program to bytecode.
//! - `vworks disasm FILE.wslb|FILE.wsl`: list the bytecode with the source beside it.
//!
//! `run`, `log` and `report` arrive with the simulation engine.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use vworks_vm::Module;
use vworks_vm::bytecode::disassemble;
use vworks_wslc::{Sources, compile, render};

#[derive(Parser, Debug)]
#[command(
    name = "vworks",
    version,
    about = "Offline-programming simulation of robot cells written in WSL"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Never colour the output (also: the NO_COLOR environment variable).
    #[arg(long, global = true)]
    no_color: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Compile programs and report every problem found (exit 1 if any is an error).
    Check {
        /// The .wsl files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Compile one program to a bytecode file.
    Build {
        /// The .wsl file.
        file: PathBuf,
        /// Output file (default: the input with extension .wslb).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// List the bytecode of a .wslb file (or compile a .wsl file and list it).
    Disasm {
        /// A .wslb or .wsl file.
        file: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let color =
        !cli.no_color && std::env::var_os("NO_COLOR").is_none() && std::io::stderr().is_terminal();
    match run(cli.command, color) {
        Ok(code) => code,
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}

fn read(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))
}

fn display(path: &Path) -> String {
    path.display().to_string()
}

/// Compiles one file, printing its diagnostics; `None` if it had errors.
fn compile_file(path: &Path, color: bool) -> Result<(Option<Module>, usize, usize), String> {
    let src = read(path)?;
    let name = display(path);
    let mut sources = Sources::new();
    sources.add(&name, &src);
    match compile(&name, &src) {
        Ok(out) => {
            eprint!("{}", render(&out.warnings, &sources, color));
            Ok((Some(out.module), 0, out.warnings.len()))
        }
        Err(e) => {
            eprint!("{}", render(&e.diagnostics, &sources, color));
            let errors = e.diagnostics.iter().filter(|d| d.is_error()).count();
            Ok((None, errors, e.diagnostics.len() - errors))
        }
    }
}

fn plural(n: usize, word: &str) -> String {
    format!("{n} {word}{}", if n == 1 { "" } else { "s" })
}

fn run(cmd: Command, color: bool) -> Result<ExitCode, String> {
    match cmd {
        Command::Check { files } => {
            let (mut errors, mut warnings) = (0, 0);
            for f in &files {
                let (_, e, w) = compile_file(f, color)?;
                errors += e;
                warnings += w;
            }
            eprintln!(
                "checked {}: {}, {}",
                plural(files.len(), "file"),
                plural(errors, "error"),
                plural(warnings, "warning")
            );
            Ok(if errors > 0 {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            })
        }
        Command::Build { file, output } => {
            let (module, errors, _) = compile_file(&file, color)?;
            let Some(module) = module else {
                eprintln!("{} not built: {}", display(&file), plural(errors, "error"));
                return Ok(ExitCode::FAILURE);
            };
            let out = output.unwrap_or_else(|| file.with_extension("wslb"));
            let bytes = module.encode();
            std::fs::write(&out, &bytes)
                .map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
            eprintln!(
                "wrote {} ({} bytes, {} instructions)",
                out.display(),
                bytes.len(),
                module.code.len()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Disasm { file } => {
            let bytes = std::fs::read(&file)
                .map_err(|e| format!("cannot read `{}`: {e}", file.display()))?;
            let (module, source) = if bytes.starts_with(&vworks_vm::bytecode::MAGIC) {
                let m = Module::decode(&bytes).map_err(|e| format!("{}: {e}", file.display()))?;
                // The source beside the listing, if it is where the module says.
                let near = file
                    .parent()
                    .map(|d| d.join(Path::new(&m.source_path).file_name().unwrap_or_default()));
                let src = std::fs::read_to_string(&m.source_path)
                    .ok()
                    .or_else(|| near.and_then(|p| std::fs::read_to_string(p).ok()));
                (m, src)
            } else {
                let (m, _, _) = compile_file(&file, color)?;
                let Some(m) = m else {
                    return Ok(ExitCode::FAILURE);
                };
                (m, read(&file).ok())
            };
            print!("{}", disassemble(&module, source.as_deref()));
            Ok(ExitCode::SUCCESS)
        }
    }
}
