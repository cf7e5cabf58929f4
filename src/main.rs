//! `pilgrim`: the command-line program of the pilgrim CAM kernel.
//!
//! Thin by design: parsing, printing and files; every computation is a
//! kernel call.

use clap::{Parser, Subcommand};
use pilgrim_kernel::machine::BUILTIN_MACHINES;
use pilgrim_kernel::{AxisKind, Machine};
use std::path::PathBuf;
use std::process::ExitCode;

/// CAM for special grinders and lathes: cold-pilger mandrels and calibers,
/// worm threads.
#[derive(Parser)]
#[command(name = "pilgrim", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in machines with their axes; with --file, read and
    /// check machine files (TOML) and list them too.
    Machines {
        /// A machine file to check and list (repeatable).
        #[arg(long = "file", value_name = "MACHINE.toml")]
        files: Vec<PathBuf>,
        /// Only the machines from --file.
        #[arg(long)]
        only_files: bool,
    },
}

fn describe(m: &Machine) -> String {
    let mut s = format!(
        "{}  ({})\n  {}\n",
        m.name(),
        m.control().unwrap_or("no control stated"),
        m.description()
    );
    for a in m.axes() {
        let range = match a.kind {
            AxisKind::Spindle => format!("up to {} rpm", a.max),
            _ => format!(
                "[{}, {}] {}, up to {} {}",
                a.to_user(a.min),
                a.to_user(a.max),
                a.unit(),
                a.to_user(a.max_feed),
                a.feed_unit()
            ),
        };
        let body = a
            .body
            .as_deref()
            .map(|b| format!(" [moves the {b}]"))
            .unwrap_or_default();
        s += &format!(
            "  {:<3} {:<8} {range}{body}",
            a.name,
            format!("{:?}", a.kind).to_lowercase()
        );
        if !a.description.is_empty() {
            s += &format!("  {}", a.description);
        }
        s.push('\n');
    }
    s
}

fn machines(files: &[PathBuf], only_files: bool) -> Result<(), String> {
    let mut out = String::new();
    if !only_files {
        for name in BUILTIN_MACHINES {
            let m = Machine::builtin(name).map_err(|e| e.to_string())?;
            out += &describe(&m);
            out.push('\n');
        }
    }
    for f in files {
        let m = Machine::from_file(f).map_err(|e| e.to_string())?;
        out += &format!("from {}:\n", f.display());
        out += &describe(&m);
        out.push('\n');
    }
    print!("{out}");
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Machines { files, only_files } => machines(files, *only_files),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("pilgrim: {e}");
            ExitCode::FAILURE
        }
    }
}
