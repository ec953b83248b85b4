//! The `piano` command. With no arguments it runs the demo: the double-escapement action
//! pressed with forces from soft to loud, with a summary table.

use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use piano_action::{ActionParams, Finger, Input, ModelKind, PianoError, TouchStyle, simulate};

/// Grand piano action simulator.
#[derive(Parser)]
#[command(
    name = "piano",
    version,
    about = "Grand piano action simulator (planar multibody)"
)]
struct Cli {
    /// Parameter file (TOML); the embedded reference action when absent.
    #[arg(long, global = true)]
    params: Option<std::path::PathBuf>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Play the double-escapement action with pressed and struck touches from soft to loud
    /// and print a summary (the default).
    Demo,
    /// Run a scenario (TOML: `model`, `duration_s`, `[input]`) and write its run directory
    /// (run.json, trajectory.csv, contacts.csv, events.json, summary.json and SVG drawings
    /// of the action at rest, let-off, string contact and check).
    Simulate {
        /// The scenario file.
        scenario: std::path::PathBuf,
        /// Output directory.
        #[arg(long)]
        out: std::path::PathBuf,
        /// Also write the interactive report, DIR/report.html.
        #[arg(long)]
        report: bool,
        /// Also write the string's bridge force as sound: a 48 kHz 16-bit mono WAV, at
        /// least 2 s long (the string rings on after the run; no damper is modelled), with
        /// 100 N as full scale so soft and loud blows keep their levels.
        #[arg(long, value_name = "FILE")]
        wav: Option<std::path::PathBuf>,
        /// Replace an earlier run in DIR (only the files a run writes are removed; your
        /// own files, such as measured.csv, stay) and an existing --wav file.
        #[arg(long)]
        force: bool,
    },
    /// Write the mechanism description of a grand model (TOML, or JSON with --json) to
    /// stdout or --out: bodies, joints, springs, contacts, the string, inputs and markers
    /// in SI units, built from the parameter file. `piano simulate` runs a scenario with
    /// `mechanism = "FILE"` from it, exactly as the built-in model.
    Describe {
        /// `simplified`, `single` or `double`.
        #[arg(long, default_value = "double")]
        model: String,
        /// JSON instead of TOML.
        #[arg(long)]
        json: bool,
        /// Write to this file instead of stdout (an existing file is not overwritten).
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Replace an existing --out file.
        #[arg(long)]
        force: bool,
    },
    /// Write the interactive report of one or more run directories: one self-contained
    /// HTML page replaying them in slow motion, to scale, with contact forces, events and
    /// linked plots.
    Report {
        /// Run directories written by `piano simulate`.
        #[arg(required = true)]
        runs: Vec<std::path::PathBuf>,
        /// The HTML file to write (default: report.html in the first run directory).
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Replace an existing report (a file that is not a report is never replaced).
        #[arg(long)]
        force: bool,
    },
    /// Write a static figure of a run for papers: hammer angle, hammer speed, key depth and
    /// contact forces against time.
    Plot {
        /// A run directory written by `piano simulate`.
        run: std::path::PathBuf,
        /// `svg` or `png`.
        #[arg(long, default_value = "svg")]
        format: String,
        /// The file to write (default: figure.svg or figure.png in the run directory);
        /// an existing file is not overwritten.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// TrueType font for the text (found on the system if not given).
        #[arg(long)]
        font: Option<std::path::PathBuf>,
        /// Replace an existing figure.
        #[arg(long)]
        force: bool,
    },
    /// Write the default parameter file (with its comments and sources) to standard output;
    /// with --list, every numeric parameter instead: path, value, unit and source tag.
    Params {
        /// List every parameter by path (of --params FILE, or the defaults) with its value,
        /// unit and source tag.
        #[arg(long)]
        list: bool,
        /// With --list: print JSON, `[{"path", "value", "unit", "tags"}]`.
        #[arg(long, requires = "list")]
        json: bool,
    },
    /// Regulate the action like a technician (front-rail punching, capstan, let-off button,
    /// drop screw, backcheck, rest rail) to the middle of the literature bands and print
    /// what it achieves: key dip, blow distance, let-off, drop, check, aftertouch (mm).
    Regulate {
        /// Which model.
        #[arg(long, default_value = "double")]
        model: String,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Also write the regulated parameter file here (refuses to overwrite a file).
        #[arg(long)]
        write: Option<std::path::PathBuf>,
    },
    /// Play one keystroke per level, in parallel on all cores, and write one CSV row per
    /// run (hammer speed, string contact, travel time, key bottom, check, ...).
    Sweep(SweepArgs),
    /// Run every literature experiment the model can reproduce (regulation, touchweight,
    /// touches from pp to ff, string contact, key motions, repetition, the 1 kg drop, the
    /// swing test) and print one table: model value, literature band, source, in or out of
    /// band, and whether an out-of-band row is a known deviation.
    Validate {
        /// Which model.
        #[arg(long, default_value = "double")]
        model: String,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Also write DIR/validation.md (the table) and DIR/validation.html (the table and
        /// plots over the published points); the folder is created if missing.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Replace validation.md and validation.html written by an earlier run.
        #[arg(long)]
        force: bool,
    },
    /// Find where measured motion and the model disagree, name the missing effect, add it
    /// and show the gap shrink. Reads a tracked-marker dataset (DIR/dataset.json and one
    /// CSV per run, schema 1) and writes OUT/report.json, report.md and report.html.
    ///
    /// Experiment `pendulum`: the hammer swing test (markers on the hammer, origin at its
    /// flange pin; runs carry `conditions.release_angle_deg`); effects pivot_viscous,
    /// air_drag, pivot_stribeck, pivot_load_friction.
    ///
    /// Experiment `key_drive`: a mass released on the key, markers on any body of the
    /// action (key, wippen, jack, repetition_lever, hammer, backcheck) in the parameter
    /// file's body frames and world frame, in metres; `"drive": "key_front"` names the
    /// marker that drives the key; runs carry `conditions.mass_kg` (required: the model's
    /// key carries it) and `conditions.release_height_m`. The drive marker is fitted, not
    /// prescribed: the key moves under the mass as a key can, the release height and the
    /// clock fitted per run. Effects key_flex, shank_flex, backcheck_compliance,
    /// keybed_felt, felt_hysteresis, knuckle_friction; confusable effects the markers
    /// cannot separate are reported as ambiguous, with the marker that would.
    Diagnose {
        /// The dataset's folder.
        dataset: std::path::PathBuf,
        /// Where to write the report (created if missing).
        #[arg(long)]
        out: std::path::PathBuf,
        /// Also write the corrected parameter file: calibrated values and the named effect
        /// as `[[effects]]`, for `piano simulate --params FILE`.
        #[arg(long, value_name = "FILE")]
        write_params: Option<std::path::PathBuf>,
        /// Only these effects of the library (comma-separated ids; default: all).
        #[arg(long)]
        library: Option<String>,
        /// Replace a report (and --write-params file) written earlier.
        #[arg(long)]
        force: bool,
    },
    /// Write a synthetic dataset with a hidden effect (or none) to test `piano diagnose`:
    /// nuisance mismatches, AR(1) camera noise, exposure, clock offset, outliers and lost
    /// frames. The truth goes to its own file, which `diagnose` never reads.
    Synth {
        /// The experiment: `pendulum` (the swing test) or `key_drive` (a mass released on
        /// the key, every marker tracked, the key front named as the drive).
        #[arg(long, default_value = "pendulum")]
        experiment: String,
        /// The hidden effect, `ID[:name=value,...]` (unset parameters take a clearly
        /// visible value); leave out for none.
        #[arg(long)]
        effect: Option<String>,
        /// The seed: the same seed gives the same dataset.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Pendulum: release angles (° above horizontal, comma-separated); the first run
        /// is fitted, the others held out.
        #[arg(long, default_value = "0,-35", allow_hyphen_values = true)]
        releases: String,
        /// Key drive: heights the mass is released from above the key (mm,
        /// comma-separated), one run each; the first is fitted, the others held out.
        #[arg(long, default_value = "0,5", allow_hyphen_values = true)]
        heights: String,
        /// Key drive: the markers tracked (comma-separated; default all: key_front,
        /// key_back, hammer_head, hammer_shank); key_front, the drive, must be one.
        #[arg(long)]
        markers: Option<String>,
        /// Key drive: the mass released on the key (kg).
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        mass: f64,
        /// Length of each run (s; 4 for a pendulum, 0.3 for a key drive).
        #[arg(long, allow_negative_numbers = true)]
        duration: Option<f64>,
        /// The dataset's folder.
        #[arg(long)]
        out: std::path::PathBuf,
        /// The truth's JSON file (outside the dataset's folder).
        #[arg(long)]
        truth: std::path::PathBuf,
        /// Replace an existing dataset and truth file.
        #[arg(long)]
        force: bool,
    },
    /// Static touchweight (down, up, balance and friction weight at the key front, in gf)
    /// from a slow simulated key descent and ascent.
    Touchweight {
        /// Which model.
        #[arg(long, default_value = "double")]
        model: String,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn plot(
    run: &std::path::Path,
    format: &str,
    out: Option<std::path::PathBuf>,
    font: Option<&std::path::Path>,
    force: bool,
) -> Result<(), String> {
    let fmt = piano_action::plot::Format::parse(format).map_err(|e| e.to_string())?;
    let path = out.unwrap_or_else(|| run.join(format!("figure.{format}")));
    check_out_file(&path, format, force)?;
    piano_action::plot::plot_run(run, fmt, &path, font).map_err(|e| e.to_string())?;
    println!("figure: {}", path.display());
    Ok(())
}

/// Checks a file a command is about to write: named `*.EXTENSION`, in a folder that exists,
/// not a folder itself, and not replacing a file unless `force` is set.
fn check_out_file(out: &std::path::Path, extension: &str, force: bool) -> Result<(), String> {
    check_file_option("--out", out, extension, force)
}

/// [`check_out_file`] for the file of option `flag`.
fn check_file_option(
    flag: &str,
    out: &std::path::Path,
    extension: &str,
    force: bool,
) -> Result<(), String> {
    let flag_error = |why: String| format!("option {flag}: {}: {why}", out.display());
    if out.extension().and_then(|e| e.to_str()) != Some(extension) {
        return Err(flag_error(format!(
            "this command writes {}, so the file must end in .{extension}",
            extension.to_uppercase()
        )));
    }
    if out.is_dir() {
        return Err(flag_error("is a folder; name a file".into()));
    }
    if let Some(parent) = out.parent()
        && !parent.as_os_str().is_empty()
        && !parent.is_dir()
    {
        return Err(flag_error(format!(
            "the folder {} does not exist",
            parent.display()
        )));
    }
    if out.exists() && !force {
        return Err(format!(
            "{}: exists; choose another {flag}, or pass --force to replace it",
            out.display()
        ));
    }
    Ok(())
}

/// Writes the report of `runs` to `out` and prints its path.
fn write_report(
    runs: &[std::path::PathBuf],
    out: &std::path::Path,
    replace: bool,
) -> Result<(), String> {
    piano_action::report::write_report(runs, out, replace).map_err(|e| e.to_string())?;
    println!("report: {}", out.display());
    Ok(())
}

fn simulate_scenario(
    params: &ActionParams,
    path: &std::path::Path,
    out: &std::path::Path,
    report: bool,
    wav: Option<&std::path::Path>,
    force: bool,
) -> Result<(), String> {
    use piano_action::scenario::{
        InputSpec, Scenario, check_run_dir, prepare_run_dir, write_pendulum_dir, write_run_dir,
    };
    let scenario = Scenario::load(path).map_err(|e| e.to_string())?;
    // Refuse an earlier run before spending time on this one; replace it (with --force)
    // only once the new run has succeeded.
    check_run_dir(out, force).map_err(|e| e.to_string())?;
    if let Some(wav) = wav {
        check_file_option("--wav", wav, "wav", force)?;
    }
    if let InputSpec::Pendulum(piano_action::scenario::PendulumSpec { release_angle_deg }) =
        scenario.input
    {
        if wav.is_some() {
            return Err("option --wav: the swing test has no string to sound; drop --wav".into());
        }
        let swing = piano_action::pendulum::swing_sampled(
            params,
            release_angle_deg,
            scenario.duration_s,
            scenario.output_step_s,
        )
        .map_err(|e| format!("{}: {e}", path.display()))?;
        prepare_run_dir(out, force).map_err(|e| e.to_string())?;
        write_pendulum_dir(out, &scenario, params, &swing).map_err(|e| e.to_string())?;
        println!(
            "hammer swing: {} turning points in {} s",
            swing.turns.len(),
            scenario.duration_s
        );
        println!("run directory: {}", out.display());
        if report {
            write_report(&[out.to_path_buf()], &out.join("report.html"), false)?;
        }
        return Ok(());
    }
    if let Some(mechanism) = &scenario.loaded_mechanism {
        if wav.is_some() {
            return Err(
                "option --wav: only the grand models sound their string; drop --wav".into(),
            );
        }
        let mut progress = Progress::new(scenario.duration_s);
        let run = scenario
            .run_mechanism(params, &mut |t| progress.update(t))
            .map_err(|e| format!("{}: {e}", path.display()));
        progress.finish();
        let run = run?;
        prepare_run_dir(out, force).map_err(|e| e.to_string())?;
        piano_action::mechanism_run::write_mechanism_run_dir(
            out,
            &scenario,
            &params.numerics,
            &run,
        )
        .map_err(|e| e.to_string())?;
        println!("{}: {} s", mechanism.name, scenario.duration_s);
        for e in &run.events {
            println!("  {:<28} {:8.2} ms", e.name, e.time_s * 1e3);
        }
        for m in &run.metrics {
            match m.value {
                Some(v) => println!("  {:<28} {v:.4} {}", m.name, m.unit),
                None => println!("  {:<28} (its event did not happen)", m.name),
            }
        }
        println!("run directory: {}", out.display());
        if report {
            write_report(&[out.to_path_buf()], &out.join("report.html"), false)?;
        }
        return Ok(());
    }
    let mut progress = Progress::new(scenario.duration_s);
    let run = scenario
        .run_observed(params, &mut |t| progress.update(t))
        .map_err(|e| match e {
            PianoError::Simulation(_) | PianoError::Integrator(_) => {
                format!("{}: {e}", path.display())
            }
            e => e.to_string(),
        });
    progress.finish();
    let run = run?;
    prepare_run_dir(out, force).map_err(|e| e.to_string())?;
    write_run_dir(out, &scenario, params, &run).map_err(|e| e.to_string())?;
    for s in &run.strikes {
        println!(
            "strike at {:.1} ms, hammer {:.2} m/s, contact {} ms, rebound {} m/s",
            s.time_s * 1e3,
            s.hammer_velocity_m_s,
            ms(s.contact_duration_s),
            s.rebound_velocity_m_s
                .map_or("-".into(), |v| format!("{v:.2}"))
        );
    }
    println!("run directory: {}", out.display());
    if let Some(wav) = wav {
        write_sound(params, &scenario, &run, wav)?;
    }
    if report {
        write_report(&[out.to_path_buf()], &out.join("report.html"), false)?;
    }
    Ok(())
}

/// Writes the run's bridge force to `wav` and prints its levels.
fn write_sound(
    params: &ActionParams,
    scenario: &piano_action::scenario::Scenario,
    run: &piano_action::Run,
    wav: &std::path::Path,
) -> Result<(), String> {
    use piano_action::sound;
    let input = scenario.input.to_input().map_err(|e| e.to_string())?;
    let kind = scenario.model_kind().map_err(|e| e.to_string())?;
    let prepared =
        piano_action::simulate::prepare(params, kind, &input).map_err(|e| e.to_string())?;
    let force = sound::bridge_force(&prepared.action, run).map_err(|e| e.to_string())?;
    let levels = sound::write_wav(wav, &force).map_err(|e| e.to_string())?;
    println!(
        "sound: {} ({:.1} s, bridge force peak {:.1} N, rms {:.1} N over the first 0.1 s{})",
        wav.display(),
        levels.seconds,
        levels.peak_n,
        levels.attack_rms_n,
        if levels.clipped > 0 {
            format!(
                ", {} samples clipped at {} N",
                levels.clipped,
                sound::FULL_SCALE_N
            )
        } else {
            String::new()
        }
    );
    Ok(())
}

/// Runs `work`, showing a spinner with `what` on standard error if it takes more than a
/// second (and standard error is a terminal).
fn with_spinner<T>(what: &str, work: impl FnOnce() -> T) -> T {
    let (done, wait) = std::sync::mpsc::channel::<()>();
    let what = what.to_string();
    let spinner = std::thread::spawn(move || {
        if wait.recv_timeout(std::time::Duration::from_secs(1)).is_ok() {
            return;
        }
        let bar = indicatif::ProgressBar::new_spinner();
        bar.set_message(what);
        if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} {msg}, {elapsed}") {
            bar.set_style(style);
        }
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        let _ = wait.recv();
        bar.finish_and_clear();
    });
    let out = work();
    let _ = done.send(());
    let _ = spinner.join();
    out
}

/// A progress bar for one simulation, on standard error: drawn only on a terminal, and only
/// once the run has taken more than a second (a keystroke takes milliseconds).
struct Progress {
    bar: indicatif::ProgressBar,
    start: std::time::Instant,
    shown: bool,
}

impl Progress {
    fn new(duration_s: f64) -> Self {
        let bar = indicatif::ProgressBar::with_draw_target(
            Some((duration_s * 1e3).ceil() as u64),
            indicatif::ProgressDrawTarget::hidden(),
        );
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} ms simulated, {elapsed} elapsed, about {eta} to go",
        ) {
            bar.set_style(style);
        }
        Progress {
            bar,
            start: std::time::Instant::now(),
            shown: false,
        }
    }

    /// The simulation has reached `t_s`.
    fn update(&mut self, t_s: f64) {
        if !self.shown {
            if self.start.elapsed().as_secs_f64() < 1.0 {
                return;
            }
            self.shown = true;
            self.bar
                .set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
        self.bar.set_position((t_s * 1e3) as u64);
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// The options of `piano sweep`.
#[derive(Args)]
struct SweepArgs {
    /// What to vary: `force` (constant key-front force, N), `pressed` (peak force of a
    /// pressed touch, N) or `struck` (finger speed, m/s).
    #[arg(long, default_value = "struck")]
    touch: String,
    /// First level (default: 1 N, 0.7 N or 0.08 m/s).
    #[arg(long, allow_negative_numbers = true)]
    from: Option<f64>,
    /// Last level (default: 40 N, 50 N or 2 m/s).
    #[arg(long, allow_negative_numbers = true)]
    to: Option<f64>,
    /// Number of runs.
    #[arg(long, default_value_t = 100, allow_negative_numbers = true)]
    runs: usize,
    /// Space the levels evenly rather than on a log scale.
    #[arg(long)]
    linear: bool,
    /// Which model (`double` by default).
    #[arg(long)]
    model: Option<String>,
    /// A mechanism description (TOML or JSON) to sweep instead of a grand model: a constant
    /// force on its first force input (`--touch force`); the CSV holds its metrics and the
    /// first time of each named event.
    #[arg(long, value_name = "FILE")]
    mechanism: Option<std::path::PathBuf>,
    /// Simulated time per run (s).
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true)]
    duration: f64,
    /// Worker threads (default: one per core; at most 256).
    #[arg(long, allow_negative_numbers = true)]
    jobs: Option<usize>,
    /// The CSV file to write (refuses to overwrite a file).
    #[arg(long)]
    out: std::path::PathBuf,
    /// Replace an existing CSV file.
    #[arg(long)]
    force: bool,
}

fn sweep(params: &ActionParams, a: SweepArgs) -> Result<(), String> {
    use piano_action::sweep::{SweepKind, csv, levels, sweep};
    let kind = match a.touch.as_str() {
        "force" => SweepKind::Force,
        "pressed" => SweepKind::Pressed,
        "struck" => SweepKind::Struck,
        other => {
            return Err(format!(
                "option --touch: unknown '{other}' (force, pressed or struck)"
            ));
        }
    };
    let (lo, hi) = match kind {
        SweepKind::Force => (1.0, 40.0),
        SweepKind::Pressed => (0.7, 50.0),
        SweepKind::Struck => (0.08, 2.0),
    };
    let mechanism = match &a.mechanism {
        None => None,
        Some(path) => {
            if a.model.is_some() {
                return Err("option --model: give either --model or --mechanism".into());
            }
            if kind != SweepKind::Force {
                return Err(format!(
                    "option --touch: a mechanism description is swept by a force (--touch \
                     force), not '{}'",
                    a.touch
                ));
            }
            Some(piano_action::mechanism::Mechanism::load(path).map_err(|e| e.to_string())?)
        }
    };
    let model = model_kind(a.model.as_deref().unwrap_or("double"))?;
    piano_action::simulate::check_duration(a.duration, 1e-3).map_err(|e| {
        format!(
            "option --duration: {}",
            e.as_input().map_or(e.to_string(), |i| i.message.clone())
        )
    })?;
    if let Some(jobs) = a.jobs
        && !(1..=256).contains(&jobs)
    {
        return Err(format!(
            "option --jobs: must be 1 to 256 worker threads, got {jobs}"
        ));
    }
    check_out_file(&a.out, "csv", a.force)?;
    let values = levels(a.from.unwrap_or(lo), a.to.unwrap_or(hi), a.runs, !a.linear)
        .map_err(|e| e.to_string())?;
    piano_action::sweep::check_levels(kind, &values).map_err(|e| e.to_string())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.jobs.unwrap_or(0))
        .build()
        .map_err(|e| format!("cannot start the worker threads: {e}"))?;
    let bar = indicatif::ProgressBar::new(values.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} runs, {elapsed} elapsed, about {eta} to go",
        )
        .map_err(|e| e.to_string())?,
    );
    let start = std::time::Instant::now();
    if let Some(mechanism) = &mechanism {
        let rows = pool.install(|| {
            piano_action::sweep::sweep_mechanism(mechanism, params, &values, a.duration, &|| {
                bar.inc(1)
            })
        });
        bar.finish_and_clear();
        let wall = start.elapsed().as_secs_f64();
        std::fs::write(&a.out, piano_action::sweep::mechanism_csv(mechanism, &rows))
            .map_err(|e| format!("{}: cannot write: {e}", a.out.display()))?;
        let failed = rows.iter().filter(|r| r.run.is_err()).count();
        println!(
            "{} force runs of {} on {} threads in {wall:.1} s wall ({:.1} ms per run); {failed} \
             failed",
            values.len(),
            mechanism.name,
            pool.current_num_threads(),
            1e3 * wall * pool.current_num_threads() as f64 / values.len().max(1) as f64,
        );
        println!("table: {}", a.out.display());
        return Ok(());
    }
    let rows = pool.install(|| sweep(params, model, kind, &values, a.duration, &|| bar.inc(1)));
    bar.finish_and_clear();
    let wall = start.elapsed().as_secs_f64();
    std::fs::write(&a.out, csv(kind, &rows))
        .map_err(|e| format!("{}: cannot write: {e}", a.out.display()))?;
    let speeds: Vec<f64> = rows
        .iter()
        .filter_map(|r| r.run.as_ref().ok())
        .filter_map(|r| r.strikes.first().map(|s| s.hammer_velocity_m_s))
        .collect();
    let failed = rows.iter().filter(|r| r.run.is_err()).count();
    println!(
        "{} {} runs of {} s on {} threads in {wall:.1} s wall ({:.1} ms per run)",
        values.len(),
        kind.name(),
        a.duration,
        pool.current_num_threads(),
        wall * 1e3 / values.len() as f64
    );
    if let (Some(min), Some(max)) = (
        speeds.iter().copied().reduce(f64::min),
        speeds.iter().copied().reduce(f64::max),
    ) {
        println!(
            "{} runs struck the string, hammer {min:.2} to {max:.2} m/s",
            speeds.len()
        );
    }
    if failed > 0 {
        println!("{failed} runs failed: see the error column");
    }
    println!("wrote {}", a.out.display());
    if failed == rows.len() {
        return Err(format!(
            "all {failed} runs failed: see the error column of {}",
            a.out.display()
        ));
    }
    Ok(())
}

fn model_kind(name: &str) -> Result<ModelKind, String> {
    ModelKind::ALL
        .into_iter()
        .find(|k| k.name() == name)
        .ok_or_else(|| {
            format!("option --model: unknown model '{name}' (simplified, single or double)")
        })
}

fn describe(
    params: &ActionParams,
    model: &str,
    json: bool,
    out: Option<&std::path::Path>,
    force: bool,
) -> Result<(), String> {
    let kind = model_kind(model)?;
    let mechanism =
        piano_action::describe::grand_description(params, kind).map_err(|e| e.to_string())?;
    let text = if json {
        mechanism.to_json_string()
    } else {
        mechanism.to_toml_string()
    }
    .map_err(|e| e.to_string())?;
    match out {
        None => {
            use std::io::Write;
            let _ = std::io::stdout().write_all(text.as_bytes());
        }
        Some(path) => {
            if path.exists() && !force {
                return Err(format!(
                    "{}: exists; pass --force to replace it",
                    path.display()
                ));
            }
            std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn touchweight(params: &ActionParams, model: &str, json: bool) -> Result<(), String> {
    let kind = model_kind(model)?;
    let w = with_spinner("measuring the touchweight", || {
        piano_action::touchweight::measure(params, kind)
    })
    .map_err(|e| e.to_string())?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&w.to_json()).map_err(|e| e.to_string())?
        );
    } else {
        println!("down weight     {:6.1} gf", w.down_weight_gf);
        println!("up weight       {:6.1} gf", w.up_weight_gf);
        println!("balance weight  {:6.1} gf", w.balance_weight_gf);
        println!("friction weight {:6.1} gf", w.friction_weight_gf);
    }
    Ok(())
}

fn validate(
    params: &ActionParams,
    model: &str,
    json: bool,
    out: Option<&std::path::Path>,
    force: bool,
) -> Result<(), String> {
    use piano_action::validate::{page, validate_with_known};
    let kind = model_kind(model)?;
    if let Some(dir) = out {
        page::check_out_dir(dir, force).map_err(|e| e.to_string())?;
    }
    let v = with_spinner("running the validation experiments", || {
        validate_with_known(params, kind)
    })
    .map_err(|e| e.to_string())?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&v.to_json()).map_err(|e| e.to_string())?
        );
    } else {
        print!("{}", v.table());
    }
    if let Some(dir) = out {
        let written = page::write_pages(&v, dir, force).map_err(|e| e.to_string())?;
        for path in written {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn regulate(
    params: &ActionParams,
    model: &str,
    json: bool,
    write: Option<&std::path::Path>,
) -> Result<(), String> {
    use piano_action::regulation::{Targets, regulate};
    let kind = model_kind(model)?;
    if let Some(path) = write
        && path.exists()
    {
        return Err(format!(
            "{}: exists; choose a new file for the regulated parameters (option --write)",
            path.display()
        ));
    }
    let done = with_spinner("regulating", || regulate(params, kind, &Targets::default()))
        .map_err(|e| e.to_string())?;
    let r = &done.achieved;
    let g = &done.params.regulation;
    if json {
        let v = done.to_json(kind).map_err(|e| e.to_string())?;
        println!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?
        );
    } else {
        let mm = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
        println!(
            "Regulated {} action ({} measurements):",
            kind.name(),
            done.measurements
        );
        println!(
            "  key dip        {:>6} mm   (9.5-11)",
            mm(Some(r.key_dip_mm))
        );
        println!(
            "  blow distance  {:>6} mm   (44-48)",
            mm(Some(r.blow_distance_mm))
        );
        println!("  let-off        {:>6} mm   (1.5-2.5)", mm(r.let_off_mm));
        println!("  drop           {:>6} mm   (0.5-2)", mm(r.drop_mm));
        println!("  check          {:>6} mm   (12-16)", mm(r.check_mm));
        println!("  aftertouch     {:>6} mm   (0.5-1.5)", mm(r.aftertouch_mm));
        println!("Settings:");
        println!("  front-rail punching top {:8.3} mm", g.front_rail_top_y_mm);
        println!("  capstan raised          {:8.3} mm", g.capstan_raise_mm);
        println!("  let-off button          {:8.3} mm", g.let_off_button_y_mm);
        println!("  drop screw              {:8.3} mm", g.drop_screw_y_mm);
        println!("  backcheck offset        {:8.3} mm", g.backcheck_offset_mm);
        println!("  rest-rail top           {:8.3} mm", g.rest_rail_top_y_mm);
        if !done.out_of_band.is_empty() {
            println!("Out of band: {}", done.out_of_band.join(", "));
        }
    }
    if let Some(path) = write {
        let text = done.params.to_toml_string().map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        eprintln!("regulated parameters written to {}", path.display());
    }
    Ok(())
}

/// `piano params --list`: every numeric parameter with its value, unit and source tag (the
/// tags read from `file`, or from the embedded defaults).
fn list_parameters(
    params: &ActionParams,
    file: Option<&std::path::Path>,
    json: bool,
) -> Result<(), String> {
    use std::fmt::Write as _;
    use std::io::Write as _;
    let source = match file {
        Some(p) => std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?,
        None => piano_action::params::DEFAULT_PARAMS_TOML.to_string(),
    };
    let list = params.parameter_list(&source).map_err(|e| e.to_string())?;
    if json {
        let rows: Vec<serde_json::Value> = list
            .iter()
            .map(|p| {
                serde_json::json!({"path": p.path, "value": p.value, "unit": p.unit, "tags": p.tags})
            })
            .collect();
        let text = serde_json::to_string_pretty(&rows).map_err(|e| e.to_string())?;
        // A closed pipe (`| head`) ends the listing quietly.
        let _ = writeln!(std::io::stdout().lock(), "{text}");
        return Ok(());
    }
    let width = list.iter().map(|p| p.path.len()).max().unwrap_or(4);
    let mut text = format!(
        "{:width$}  {:>14}  {:10}  source\n",
        "path", "value", "unit"
    );
    for p in &list {
        let _ = writeln!(
            text,
            "{:width$}  {:>14}  {:10}  {}",
            p.path,
            format!("{}", p.value),
            p.unit,
            p.tags
        );
    }
    let _ = writeln!(text, "{} parameters", list.len());
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
    Ok(())
}

fn load(path: Option<&std::path::Path>) -> Result<ActionParams, String> {
    match path {
        None => Ok(ActionParams::reference()),
        Some(p) => ActionParams::load(p).map_err(|e| e.to_string()),
    }
}

fn ms(t: Option<f64>) -> String {
    t.map_or("-".into(), |t| format!("{:.1}", t * 1e3))
}

fn demo(params: &ActionParams) -> Result<(), String> {
    println!("Double-escapement grand action played by a finger, soft to loud.");
    println!("pressed: the finger rests on the key, its force rising to the peak in 30 ms;");
    println!("struck: the finger lands on the key at the given speed, the arm pushing on.");
    println!("Times in ms from the key's start (0.1 mm down); hammer speed at the string.\n");
    println!(
        "{:>18} {:>8} {:>8} {:>8} {:>11} {:>8} {:>10} {:>7}",
        "touch", "let-off", "strike", "v (m/s)", "contact", "check", "key bottom", "vs HS"
    );
    let touches = [
        TouchStyle::Pressed { peak_force_n: 1.0 },
        TouchStyle::Pressed { peak_force_n: 3.0 },
        TouchStyle::Pressed { peak_force_n: 10.0 },
        TouchStyle::Pressed { peak_force_n: 40.0 },
        TouchStyle::Struck {
            finger_speed_m_s: 0.15,
        },
        TouchStyle::Struck {
            finger_speed_m_s: 0.4,
        },
        TouchStyle::Struck {
            finger_speed_m_s: 0.8,
        },
        TouchStyle::Struck {
            finger_speed_m_s: 1.6,
        },
    ];
    for style in touches {
        let run = simulate(
            params,
            ModelKind::Double,
            &Input::Touch {
                style,
                finger: Finger::default(),
            },
            0.3,
            1e-3,
        )
        .map_err(|e| e.to_string())?;
        let label = match style {
            TouchStyle::Pressed { peak_force_n } => format!("pressed {peak_force_n:.0} N"),
            TouchStyle::Struck { finger_speed_m_s } => {
                format!("struck {finger_speed_m_s:.2} m/s")
            }
        };
        let t0 = run.key_start_time_s.unwrap_or(0.0);
        let from_start = |t: Option<f64>| ms(t.map(|t| t - t0));
        let strike = run.strikes.first();
        println!(
            "{:>18} {:>8} {:>8} {:>8} {:>11} {:>8} {:>10} {:>7}",
            label,
            from_start(run.let_off_time_s),
            from_start(strike.map(|s| s.time_s)),
            strike.map_or("-".into(), |s| format!("{:.2}", s.hammer_velocity_m_s)),
            ms(strike.and_then(|s| s.contact_duration_s)),
            from_start(run.check_time_s),
            from_start(run.key_bottom_time_s),
            ms(run.key_bottom_time_s.zip(strike).map(|(k, s)| k - s.time_s)),
        );
    }
    println!("\n`vs HS`: key bottom minus string contact (ms). `piano --help` for more;");
    println!("`piano params` writes the parameter file, `--params FILE` loads your own.");
    demo_report(params)
}

/// Writes a pressed and a struck touch of about the same loudness as run directories in
/// the temporary folder, and their report side by side.
fn demo_report(params: &ActionParams) -> Result<(), String> {
    use piano_action::scenario::{
        InputSpec, Scenario, TouchStyleName, prepare_run_dir, write_run_dir,
    };
    let root = std::env::temp_dir().join("piano-demo");
    let touch = |style, peak_force_n, finger_speed_m_s| {
        InputSpec::Touch(piano_action::scenario::TouchSpec {
            style,
            peak_force_n,
            finger_speed_m_s,
            finger_mass_g: None,
            rise_s: None,
            arm_damping_n_s_m: None,
        })
    };
    let mut dirs = Vec::new();
    for (name, input) in [
        (
            "pressed-10N",
            touch(TouchStyleName::Pressed, Some(10.0), None),
        ),
        (
            "struck-0.8m_s",
            touch(TouchStyleName::Struck, None, Some(0.8)),
        ),
    ] {
        let scenario = Scenario {
            model: "double".into(),
            mechanism: None,
            settle_s: None,
            duration_s: 0.1,
            output_step_s: 5e-4,
            input,
            loaded_mechanism: None,
        };
        let run = scenario.run(params).map_err(|e| e.to_string())?;
        let dir = root.join(name);
        // The demo's own folder in the temporary directory: replace the last demo's run.
        prepare_run_dir(&dir, true).map_err(|e| e.to_string())?;
        write_run_dir(&dir, &scenario, params, &run).map_err(|e| e.to_string())?;
        dirs.push(dir);
    }
    println!("\nA pressed and a struck touch of about the same loudness, in slow motion:");
    write_report(&dirs, &root.join("report.html"), true)
}

/// `piano diagnose`.
fn diagnose(
    params: &piano_action::params::ActionParams,
    params_file: Option<&std::path::Path>,
    dataset: &std::path::Path,
    out: &std::path::Path,
    write_params: Option<&std::path::Path>,
    library: Option<&str>,
    force: bool,
) -> Result<(), String> {
    use piano_action::identify::commands::{Diagnosed, diagnose_dataset_to_disk};
    let source = match params_file {
        Some(p) => std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?,
        None => piano_action::params::DEFAULT_PARAMS_TOML.to_string(),
    };
    let bar = stage_bar();
    let progress = stage_progress(&bar);
    let result = diagnose_dataset_to_disk(
        params,
        &source,
        dataset,
        library,
        out,
        write_params,
        force,
        &progress,
    );
    bar.finish_and_clear();
    let outcome = match result.map_err(|e| e.to_string())? {
        Diagnosed::Pendulum(outcome) => *outcome,
        Diagnosed::KeyDrive(d, written) => {
            print_key_drive(&d, &written);
            return Ok(());
        }
    };
    let (d, written) = (&outcome.diagnosis, &outcome.written);
    println!("decision: {}. {}", d.decision, d.summary);
    let g = &d.gap;
    println!(
        "gap (RMS per coordinate): fitted {:.1} -> {:.1} um, held-out {:.1} -> {:.1} um, noise floor {:.1} um",
        g.before_rms_m * 1e6,
        g.after_rms_m * 1e6,
        g.heldout_before_rms_m * 1e6,
        g.heldout_after_rms_m * 1e6,
        g.noise_floor_m * 1e6
    );
    for c in &d.candidates {
        println!("  {:<22} dBIC {:>9.1}  {}", c.id, c.delta_bic, c.why);
    }
    if !d.at_bound.is_empty() {
        eprintln!(
            "warning: {} ended at the edge of the search range",
            d.at_bound.join(", ")
        );
    }
    for line in piano_action::identify::report::throughput_lines(&d.throughput) {
        println!("{line}");
    }
    for p in written {
        println!("wrote {}", p.display());
    }
    if let Some(why) = &outcome.params_refused {
        eprintln!("note: {why}");
    }
    Ok(())
}

/// A progress bar for a diagnosis's stages (0–100).
fn stage_bar() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(100);
    if let Ok(style) = indicatif::ProgressStyle::with_template("{bar:30} {msg} ({elapsed})") {
        bar.set_style(style);
    }
    bar
}

/// What a diagnosis reports of its stages, shown on `bar`.
fn stage_progress(bar: &indicatif::ProgressBar) -> impl Fn(&str, f64) + Sync + '_ {
    move |msg: &str, fraction: f64| {
        bar.set_message(msg.to_string());
        bar.set_position((fraction * 100.0) as u64);
    }
}

/// What `piano diagnose` prints of a key-drive diagnosis.
fn print_key_drive(
    d: &piano_action::identify::key_diagnose::KeyDriveDiagnosis,
    written: &[std::path::PathBuf],
) {
    use piano_action::identify::key_report;
    println!("decision: {}. {}", d.decision, d.summary);
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.1}", v * 1e6));
    println!(
        "gap (RMS per coordinate): fitted {:.1} -> {:.1} um, held-out {} -> {} um, noise floor {:.1} um",
        d.before_rms_m * 1e6,
        d.after_rms_m * 1e6,
        opt(d.heldout_before_rms_m),
        opt(d.heldout_after_rms_m),
        d.noise_floor_m * 1e6
    );
    if let Some((b, a)) = key_report::post_check_gap(d) {
        println!(
            "gap after the check's catch: {:.1} -> {:.1} um ({:.1}x)",
            b * 1e6,
            a * 1e6,
            b / a.max(1e-300)
        );
    }
    println!(
        "flagged: {} phase, worst on {}{}",
        d.flagged_phase,
        d.flagged_marker,
        d.onset.as_ref().map_or(String::new(), |o| format!(
            "; onset {:.1} ms ({}{})",
            o.time_s * 1e3,
            o.marker,
            o.after_event
                .as_ref()
                .map_or(String::new(), |(e, dt)| format!(
                    ", {:.1} ms after {e}",
                    dt * 1e3
                ))
        ))
    );
    for c in &d.candidates {
        println!("  {:<22} dBIC {:>9.1}  {}", c.id, c.delta_bic, c.why);
    }
    let total: f64 = d.timing.iter().map(|(_, t)| t).sum();
    println!(
        "time: {total:.1} s ({})",
        d.timing
            .iter()
            .map(|(s, t)| format!("{s} {t:.1} s"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    for line in piano_action::identify::report::throughput_lines(&d.throughput) {
        println!("  {line}");
    }
    for p in written {
        println!("wrote {}", p.display());
    }
}

/// `piano synth`.
#[allow(clippy::too_many_arguments)]
fn synth(
    params: &piano_action::params::ActionParams,
    experiment: &str,
    effect: Option<&str>,
    seed: u64,
    (releases, heights, mass, markers): (&str, &str, f64, Option<&str>),
    duration: Option<f64>,
    out: &std::path::Path,
    truth: &std::path::Path,
    force: bool,
) -> Result<(), String> {
    use piano_action::identify::commands::{SynthRequest, synth_request_to_disk};
    let numbers = |flag: &str, text: &str| {
        text.split(',')
            .map(|r| {
                r.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("option {flag}: '{r}' is not a number"))
            })
            .collect::<Result<Vec<_>, _>>()
    };
    let key_drive = experiment == piano_action::identify::key_drive::EXPERIMENT;
    // The experiment and the options that do not apply to it first, as they always were;
    // then the numbers.
    if !key_drive && experiment != "pendulum" {
        return Err(format!(
            "option --experiment: '{experiment}': 'pendulum' or 'key_drive'"
        ));
    }
    if !key_drive && markers.is_some() {
        return Err(
            "option --markers: the key drive's; a pendulum dataset tracks the \
                    hammer's head and shank"
                .into(),
        );
    }
    if let (true, Some(e)) = (key_drive, effect) {
        piano_action::identify::action_effects::ActionEffect::parse(e)
            .map_err(|e| e.to_string())?;
    }
    let request = SynthRequest {
        experiment: experiment.to_string(),
        effect: effect.map(str::to_string),
        seed,
        // Only the experiment's own list is read (a wrong other one is not an error).
        releases_deg: if key_drive {
            Vec::new()
        } else {
            numbers("--releases", releases)?
        },
        heights_mm: if key_drive {
            numbers("--heights", heights)?
        } else {
            Vec::new()
        },
        markers: markers.map(|m| {
            m.split(',')
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty())
                .collect()
        }),
        mass_kg: mass,
        duration_s: duration,
    };
    let done =
        synth_request_to_disk(params, &request, out, truth, force).map_err(|e| e.to_string())?;
    if key_drive {
        println!(
            "dataset: {} ({} run(s) of {} s at {} fps, {} kg on the key, the key front \
             as the drive)\ntruth: {}",
            out.display(),
            done.runs,
            done.duration_s,
            done.fps,
            mass,
            truth.display()
        );
    } else {
        println!(
            "dataset: {} ({} run{} of {} s at {} fps)\ntruth: {}",
            out.display(),
            done.runs,
            if done.runs == 1 { "" } else { "s" },
            done.duration_s,
            done.fps,
            truth.display()
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or(Command::Demo);
    // `plot`, `report` and `params` use no parameter file: say so rather than ignore one.
    let unused = match &command {
        Command::Plot { .. } => Some("plot (the run directory holds its parameters)"),
        Command::Report { .. } => Some("report (the run directories hold their parameters)"),
        Command::Params { list: false, .. } => Some("params (it writes the default file)"),
        _ => None,
    };
    let result = match (unused, cli.params.as_deref()) {
        (Some(what), Some(_)) => Err(format!(
            "option --params: not used by `piano {what}`; leave it out"
        )),
        _ => load(cli.params.as_deref()).and_then(|params| match command {
            Command::Demo => demo(&params),
            Command::Touchweight { model, json } => touchweight(&params, &model, json),
            Command::Describe {
                model,
                json,
                out,
                force,
            } => describe(&params, &model, json, out.as_deref(), force),
            Command::Validate {
                model,
                json,
                out,
                force,
            } => validate(&params, &model, json, out.as_deref(), force),
            Command::Regulate { model, json, write } => {
                regulate(&params, &model, json, write.as_deref())
            }
            Command::Simulate {
                scenario,
                out,
                report,
                wav,
                force,
            } => simulate_scenario(&params, &scenario, &out, report, wav.as_deref(), force),
            Command::Plot {
                run,
                format,
                out,
                font,
                force,
            } => plot(&run, &format, out, font.as_deref(), force),
            Command::Report { runs, out, force } => {
                let out = out.unwrap_or_else(|| runs[0].join("report.html"));
                write_report(&runs, &out, force)
            }
            Command::Sweep(args) => sweep(&params, args),
            Command::Diagnose {
                dataset,
                out,
                write_params,
                library,
                force,
            } => diagnose(
                &params,
                cli.params.as_deref(),
                &dataset,
                &out,
                write_params.as_deref(),
                library.as_deref(),
                force,
            ),
            Command::Synth {
                experiment,
                effect,
                seed,
                releases,
                heights,
                markers,
                mass,
                duration,
                out,
                truth,
                force,
            } => synth(
                &params,
                &experiment,
                effect.as_deref(),
                seed,
                (&releases, &heights, mass, markers.as_deref()),
                duration,
                &out,
                &truth,
                force,
            ),
            Command::Params { list: false, .. } => {
                use std::io::Write;
                let _ = std::io::stdout()
                    .write_all(piano_action::params::DEFAULT_PARAMS_TOML.as_bytes());
                Ok(())
            }
            Command::Params { list: true, json } => {
                list_parameters(&params, cli.params.as_deref(), json)
            }
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
