//! `pilgrim`: the command-line program of the pilgrim CAM kernel.
//!
//! Thin by design: parsing, printing and files; every computation is a
//! kernel call. Exit codes: 0 done, 1 the job failed (the message says
//! why, naming file, line, parameter or block), 2 a bad command line.

mod compensate;
mod counting;
mod run;

use clap::{Parser, Subcommand};
use pilgrim_kernel::catalog::{Catalog, CompiledPlugin, Origin};
use pilgrim_kernel::job::Formats;
use pilgrim_kernel::machine::{machine_file, AxisKind, MachineInfo};
use pilgrim_kernel::plugin::PluginMachine;
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::PartFamily;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The allocator, counting per thread what each holds, so that a script's
/// memory limit is looked at after every operation
/// (`pilgrim_kernel::script::set_allocated_probe`).
#[global_allocator]
static ALLOCATOR: counting::Counting = counting::Counting;

/// `crate::entry` of each plugin compiled in, as its entry symbol.
macro_rules! compiled {
    ($($krate:ident :: $entry:ident),* $(,)?) => {
        [$(CompiledPlugin { symbol: stringify!($entry), entry: $krate::$entry }),*]
    };
}

/// The machine plugins compiled into the program: a machine crate under
/// `plugins/` (its dependency in Cargo.toml) and one line here.
const COMPILED_PLUGINS: &[CompiledPlugin] = &compiled![
    grinder_3k152vf20::pilgrim_plugin_grinder_3k152vf20,
    lz_250::pilgrim_plugin_lz_250,
    mannesmann::pilgrim_plugin_mannesmann,
    fanuc_0i_tc::pilgrim_plugin_fanuc_0i_tc,
];

/// CAM for special grinders and lathes: cold-pilger mandrels and calibers,
/// worm threads.
#[derive(Parser)]
#[command(name = "pilgrim", version, about, long_about = None)]
struct Cli {
    /// Print nothing but errors.
    #[arg(long, short, global = true)]
    quiet: bool,
    /// Time limit of a plugin library's loading and of each of its calls
    /// (seconds): a plugin past it is stopped and named in the error.
    #[arg(long, value_name = "S", global = true, default_value_t = 30.0)]
    plugin_seconds: f64,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a part family: toolpath, program and report into --out.
    Run {
        /// The family's script (.rhai).
        script: PathBuf,
        /// Parameter values from a TOML file (name = value).
        #[arg(long, value_name = "FILE.toml")]
        params: Option<PathBuf>,
        /// A parameter value (repeatable); wins over --params.
        #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_set)]
        sets: Vec<(String, String)>,
        /// The machine: a built-in's name, a plugin (.so), a machine file
        /// (.toml) or a machine script (.rhai). Default: the family's
        /// default_machine().
        #[arg(long)]
        machine: Option<String>,
        /// The output directory (replaced as a whole when the run succeeds).
        /// Default: out/<script name>.
        #[arg(long)]
        out: Option<PathBuf>,
        /// The block (from 1) to place the tool at in the 3-D models.
        /// Default: the middle block of the last cutting pass.
        #[arg(long, value_name = "N")]
        pose_block: Option<usize>,
        /// Chordal tolerance of the 3-D models (mm); the family's own
        /// tolerances are parameters (--set).
        #[arg(long, value_name = "MM", default_value_t = pilgrim_kernel::mesh::DEFAULT_TOLERANCE)]
        mesh_tolerance: f64,
        /// Largest deviation of the STEP solids' B-splines from the
        /// family's profile (mm).
        #[arg(long, value_name = "MM", default_value_t = pilgrim_kernel::step::DEFAULT_TOLERANCE)]
        step_tolerance: f64,
        /// Write the STL files as ASCII instead of binary.
        #[arg(long)]
        stl_ascii: bool,
        /// Also write the scene as scene.gltf + scene.bin.
        #[arg(long)]
        gltf: bool,
        /// Wall-clock limit of each call of the family's script (seconds),
        /// kernel calls made from it included.
        #[arg(long, value_name = "S", default_value_t = 60.0)]
        script_seconds: f64,
        /// Memory the family's script may hold (MB), looked at after every operation.
        #[arg(long, value_name = "MB", default_value_t = 4096)]
        script_memory_mb: u64,
        /// Wall-clock limit of the whole run (seconds): checked inside the
        /// kernel's long loops (the rest's track, replays, posts, lints).
        #[arg(long, value_name = "S", default_value_t = 600.0)]
        run_seconds: f64,
        /// Write a whole program numbered N (Fanuc: `%`, `O` number, the
        /// tool call) instead of the block to paste after the tool call.
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=9999))]
        program_number: Option<u32>,
        /// Also write the program in this dialect (repeatable): `linuxcnc`
        /// (`program.ngc`), `sinumerik`, `fanuc`.
        #[arg(long = "post", value_name = "DIALECT")]
        also_post: Vec<String>,
    },
    /// Verify a program as its control reads it: a run's (its output
    /// directory, after the program was edited by hand), or any program
    /// file for a machine and a family. Writes the verification's report
    /// (report.json, report.html, plots) into --out; exits 1 naming the
    /// block where the program fails.
    Verify {
        /// A run's output directory, or a program file.
        target: PathBuf,
        /// The family's script (.rhai). Default for a run's directory: the
        /// script the run names.
        #[arg(long)]
        family: Option<PathBuf>,
        /// The machine: a built-in's name, a plugin (.so), a machine file
        /// (.toml). Default: the run's built-in machine, or the family's
        /// default_machine().
        #[arg(long)]
        machine: Option<String>,
        /// Parameter values from a TOML file; for a run's directory they win
        /// over the run's own.
        #[arg(long, value_name = "FILE.toml")]
        params: Option<PathBuf>,
        /// A parameter value (repeatable); wins over --params.
        #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_set)]
        sets: Vec<(String, String)>,
        /// The shop's offset table (TOML): the shift of each tool offset
        /// other than the tool call's (D2, T0102) and each work offset
        /// other than the first (G55); the program may then select them.
        #[arg(long, value_name = "FILE.toml")]
        offsets: Option<PathBuf>,
        /// Where the report goes. Default: TARGET.verify beside the target.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Wall-clock limit of each call of the family's script (seconds).
        #[arg(long, value_name = "S", default_value_t = 60.0)]
        script_seconds: f64,
        /// Wall-clock limit of the whole verification (seconds).
        #[arg(long, value_name = "S", default_value_t = 600.0)]
        run_seconds: f64,
    },
    /// Re-export a finished run's 3-D scene with the tool at another block.
    Export {
        /// The run's output directory.
        dir: PathBuf,
        /// The machine, when the run's is not a built-in: a plugin (.so), a
        /// machine file (.toml) or script (.rhai). pilgrim never opens one
        /// the run's files name.
        #[arg(long)]
        machine: Option<String>,
        /// The block (from 1). Default: the middle block of the last
        /// cutting pass.
        #[arg(long, value_name = "N")]
        block: Option<usize>,
        /// Write the STL files as ASCII instead of binary.
        #[arg(long)]
        stl_ascii: bool,
        /// Also write the scene as scene.gltf + scene.bin.
        #[arg(long)]
        gltf: bool,
    },
    /// Correct a run by its finished part as measured: the measured minus
    /// the nominal fitted within the measurement's uncertainty (a cubic
    /// smoothing spline), the target moved against it by the gain, and the
    /// job run again on the corrected target into --out, verified as
    /// usual; `compensation.json` and `correction.csv` beside its files.
    Compensate {
        /// The run's output directory.
        dir: PathBuf,
        /// The measurement: a table (CSV, XLSX, ODS) whose columns the
        /// family names (the mandrel: z_mm and d_mm or r_mm; the caliber:
        /// theta_deg and Hp_mm, B_mm or both; a thread: z_mm, d2_mm, and
        /// start for several starts).
        #[arg(long, value_name = "FILE")]
        measured: PathBuf,
        /// The share of the measured error the target moves against (1:
        /// all of it).
        #[arg(long, default_value_t = 1.0)]
        gain: f64,
        /// The measurement's uncertainty (mm): the fit's residual.
        #[arg(long, value_name = "MM", default_value_t = 0.001)]
        uncertainty: f64,
        /// The largest correction accepted (mm); a larger one is refused,
        /// naming where: a bound against a wrong measurement (a diameter
        /// read as a radius, another part's file), not the part's tolerance.
        #[arg(long, value_name = "MM", default_value_t = 0.1)]
        limit: f64,
        /// The measurement's columns by the family's names, as a measuring
        /// program names them: `z="Position Z [mm]",d="Istwert D [mm]"`
        /// (each NAME the family's column, `z_mm`, or its name before the
        /// unit, `z`; each COLUMN a header, a letter or a number). Only the
        /// columns mapped are read.
        #[arg(long, value_name = "NAME=COLUMN,...", value_parser = column_map)]
        columns: Option<ColumnMap>,
        /// Where the corrected run goes. Default: DIR-compensated.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Wall-clock limit of each call of the family's script (seconds).
        #[arg(long, value_name = "S", default_value_t = 60.0)]
        script_seconds: f64,
        /// Wall-clock limit of the whole compensation (seconds).
        #[arg(long, value_name = "S", default_value_t = 600.0)]
        run_seconds: f64,
    },
    /// List the built-in machines; with --plugin or --file, those too.
    Machines {
        /// A plugin library to load and list (repeatable).
        #[arg(long = "plugin", value_name = "LIB")]
        plugins: Vec<PathBuf>,
        /// A machine file to check and list (repeatable).
        #[arg(long = "file", value_name = "MACHINE.toml")]
        files: Vec<PathBuf>,
        /// Only the machines from --plugin and --file.
        #[arg(long)]
        only_files: bool,
        /// Print this machine (a built-in's name, a plugin or a file) as a
        /// machine file instead: the start of a shop's own.
        #[arg(long, value_name = "MACHINE", conflicts_with_all = ["plugins", "files", "only_files"])]
        toml: Option<String>,
    },
    /// List a family's parameters: name, default, unit, description.
    Params {
        /// The family's script (.rhai).
        script: PathBuf,
    },
    /// Load a plugin (in a child process), try its kinematics over the
    /// travel and print its descriptor, or say exactly why not.
    PluginCheck {
        /// The shared library.
        lib: PathBuf,
    },
    /// Serve a plugin library to its host (the child process that holds a
    /// library's code; not for direct use).
    #[command(hide = true)]
    PluginServer {
        /// The library.
        lib: PathBuf,
        /// Its entry symbol.
        symbol: String,
    },
    /// Write the script API reference (Markdown).
    ApiDocs {
        /// Where to write it; standard output if not given.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn parse_set(s: &str) -> Result<(String, String), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("'{s}' is not NAME=VALUE"))?;
    Ok((k.trim().to_owned(), v.to_owned()))
}

fn describe(info: &MachineInfo, origin: &Origin) -> String {
    let origin = match origin.to_string() {
        o if o.is_empty() => o,
        o => format!(", {o}"),
    };
    let mut s = format!(
        "{}  ({}){origin}\n  {}\n",
        info.name, info.control, info.description
    );
    for a in &info.axes {
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
            .or_else(|| a.turns_part.then(|| " [turns the part]".to_owned()))
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

fn list_machines(
    catalog: &Catalog,
    plugins: &[PathBuf],
    files: &[PathBuf],
    only_files: bool,
) -> Result<String, String> {
    let mut specs: Vec<String> = if only_files {
        vec![]
    } else {
        catalog.builtin_names()
    };
    specs.extend(plugins.iter().chain(files).map(|p| p.display().to_string()));
    let mut out = String::new();
    for spec in specs {
        let m = catalog.open(&spec).map_err(|e| e.to_string())?;
        out += &describe(m.kinematics.info(), &m.origin);
        out.push('\n');
    }
    Ok(out)
}

fn params(script: &Path) -> Result<String, String> {
    let fam = ScriptFamily::load(script, &Limits::default(), &Access::default())
        .map_err(|e| e.to_string())?;
    let mut rows = vec![(
        "name".to_owned(),
        "default".to_owned(),
        "unit".to_owned(),
        "description".to_owned(),
    )];
    for p in fam.params() {
        rows.push((p.name.clone(), p.default.to_string(), p.unit.clone(), {
            let mut d = p.doc.clone();
            let range = p.range_text();
            if !range.is_empty() {
                d += &format!(" ({range})");
            }
            if let Some(m) = &p.machine {
                d += &format!(" (default: the machine's constant {m})");
            }
            d
        }));
    }
    let w0 = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
    let w1 = rows.iter().map(|r| r.1.len()).max().unwrap_or(0);
    let w2 = rows.iter().map(|r| r.2.len()).max().unwrap_or(0);
    Ok(rows
        .iter()
        .map(|r| format!("{:<w0$}  {:<w1$}  {:<w2$}  {}\n", r.0, r.1, r.2, r.3))
        .collect())
}

fn plugin_check(lib: &Path) -> Result<String, String> {
    use pilgrim_kernel::MachineKinematics;
    let (m, tried) = PluginMachine::load_checked(lib).map_err(|e| e.to_string())?;
    let (major, minor) = m.abi_version();
    let descriptor = serde_json::to_string_pretty(m.info()).map_err(|e| e.to_string())?;
    Ok(format!(
        "{}: pilgrim machine plugin, ABI {major}.{minor}, machine {} ({}), solves {}\n{tried}{descriptor}\n",
        m.origin(),
        m.info().name,
        m.info().control,
        m.info().solved_axes.join(", ")
    ))
}

fn main() -> ExitCode {
    // A panic is a defect: said short, escaped, with where it happened.
    std::panic::set_hook(Box::new(|info| {
        eprintln!(
            "pilgrim: {}",
            pilgrim_kernel::error::panic_text(info.payload(), info.location())
        );
    }));
    let cli = Cli::parse();
    if let Command::PluginServer { lib, symbol } = &cli.command {
        let code = pilgrim_kernel::plugin::server::serve(lib, symbol);
        return ExitCode::from(u8::try_from(code).unwrap_or(3));
    }
    pilgrim_kernel::script::set_allocated_probe(counting::held);
    let Ok(seconds) = std::time::Duration::try_from_secs_f64(cli.plugin_seconds)
        .map_err(|_| ())
        .and_then(|d| if d.is_zero() { Err(()) } else { Ok(d) })
    else {
        eprintln!(
            "pilgrim: --plugin-seconds {} must be a positive number of seconds",
            cli.plugin_seconds
        );
        return ExitCode::from(2);
    };
    pilgrim_kernel::plugin::configure(
        None,
        pilgrim_kernel::plugin::Bounds {
            load: seconds,
            call: seconds,
        },
    );
    let catalog = match Catalog::new(COMPILED_PLUGINS) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("pilgrim: a compiled-in machine plugin is broken: {e}");
            return ExitCode::FAILURE;
        }
    };
    let result = match &cli.command {
        Command::Run {
            script,
            params,
            sets,
            machine,
            out,
            pose_block,
            mesh_tolerance,
            step_tolerance,
            stl_ascii,
            gltf,
            script_seconds,
            script_memory_mb,
            run_seconds,
            program_number,
            also_post,
        } => run::run(
            &run::RunArgs {
                formats: Formats {
                    stl_ascii: *stl_ascii,
                    gltf: *gltf,
                },
                pose_block: *pose_block,
                mesh_tolerance: *mesh_tolerance,
                step_tolerance: *step_tolerance,
                script: script.clone(),
                params: params.clone(),
                sets: sets.clone(),
                machine: machine.clone(),
                out: out.clone().unwrap_or_else(|| {
                    PathBuf::from("out").join(script.file_stem().unwrap_or_else(|| "run".as_ref()))
                }),
                quiet: cli.quiet,
                script_seconds: *script_seconds,
                script_memory_mb: *script_memory_mb,
                run_seconds: *run_seconds,
                program_number: *program_number,
                also_post: also_post.clone(),
            },
            &catalog,
        )
        .map(|s| s + "\n"),
        Command::Machines {
            toml: Some(spec), ..
        } => catalog
            .open(spec)
            .map(|m| {
                let origin = match m.origin.to_string() {
                    o if o.is_empty() => format!("the built-in {spec}"),
                    o => format!("{spec}, {o}"),
                };
                machine_file(m.kinematics.info(), &origin)
            })
            .map_err(|e| e.to_string()),
        Command::Machines {
            plugins,
            files,
            only_files,
            toml: None,
        } => list_machines(&catalog, plugins, files, *only_files),
        Command::Export {
            dir,
            machine,
            block,
            stl_ascii,
            gltf,
        } => run::export(
            dir,
            &catalog,
            machine.as_deref(),
            *block,
            Formats {
                stl_ascii: *stl_ascii,
                gltf: *gltf,
            },
        )
        .map(|s| s + "\n"),
        Command::Verify {
            target,
            family,
            machine,
            params,
            sets,
            offsets,
            out,
            script_seconds,
            run_seconds,
        } => run::verify(
            &run::VerifyArgs {
                target: target.clone(),
                family: family.clone(),
                machine: machine.clone(),
                params: params.clone(),
                sets: sets.clone(),
                offsets: offsets.clone(),
                out: out.clone().unwrap_or_else(|| {
                    let mut o = target.clone().into_os_string();
                    o.push(".verify");
                    PathBuf::from(o)
                }),
                script_seconds: *script_seconds,
                run_seconds: *run_seconds,
            },
            &catalog,
        )
        .map(|s| s + "\n"),
        Command::Compensate {
            dir,
            measured,
            gain,
            uncertainty,
            limit,
            columns,
            out,
            script_seconds,
            run_seconds,
        } => compensate::compensate(
            &compensate::CompensateArgs {
                dir: dir.clone(),
                measured: measured.clone(),
                gain: *gain,
                uncertainty: *uncertainty,
                limit: *limit,
                columns: columns.clone().map(|c| c.0).unwrap_or_default(),
                out: out.clone().unwrap_or_else(|| compensate::default_out(dir)),
                script_seconds: *script_seconds,
                run_seconds: *run_seconds,
            },
            &catalog,
        )
        .map(|s| s + "\n"),
        Command::Params { script } => params(script),
        Command::PluginCheck { lib } => plugin_check(lib),
        Command::PluginServer { .. } => Err("the plugin server runs before anything else".into()),
        Command::ApiDocs { out } => {
            let text = pilgrim_kernel::script::api_reference();
            match out {
                // A new file, or the reference an earlier api-docs wrote
                // (its heading and the line saying so), never a user's.
                Some(p) => pilgrim_kernel::output::write_generated_file(p, text.as_bytes(), 3)
                    .map(|_| String::new())
                    .map_err(|e| e.to_string()),
                None => Ok(text),
            }
        }
    };
    match result {
        Ok(text) => {
            // --quiet silences a status line, never the data asked for.
            let status = matches!(
                cli.command,
                Command::Run { .. }
                    | Command::Verify { .. }
                    | Command::Compensate { .. }
                    | Command::Export { .. }
                    | Command::PluginCheck { .. }
            );
            if cli.quiet && status {
                return ExitCode::SUCCESS;
            }
            // A status line is a message, cut at its length; data is whole.
            let cut = status.then_some(pilgrim_kernel::files::MAX_MESSAGE);
            let text = pilgrim_kernel::files::terminal(&text, cut);
            let mut stdout = std::io::stdout().lock();
            match stdout
                .write_all(text.as_bytes())
                .and_then(|()| stdout.flush())
            {
                Ok(()) => ExitCode::SUCCESS,
                // The reader closed the pipe: it has read what it wanted.
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("pilgrim: the output could not be written: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Err(e) => {
            eprintln!(
                "pilgrim: {}",
                pilgrim_kernel::files::terminal(&e, Some(pilgrim_kernel::files::MAX_MESSAGE))
            );
            ExitCode::FAILURE
        }
    }
}

/// `--columns`' value: (NAME, COLUMN) pairs.
#[derive(Debug, Clone)]
struct ColumnMap(Vec<(String, String)>);

/// `--columns`' value: `NAME=COLUMN` pairs separated by commas (a
/// column's header may hold spaces and brackets, not a comma).
fn column_map(text: &str) -> Result<ColumnMap, String> {
    text.split(',')
        .map(|pair| {
            let (name, column) = pair
                .split_once('=')
                .ok_or_else(|| format!("'{pair}' is not NAME=COLUMN"))?;
            let unquote = |s: &str| s.trim().trim_matches('"').trim().to_owned();
            let (name, column) = (unquote(name), unquote(column));
            if name.is_empty() || column.is_empty() {
                return Err(format!("'{pair}' is not NAME=COLUMN"));
            }
            Ok((name, column))
        })
        .collect::<Result<_, _>>()
        .map(ColumnMap)
}
