//! The `steradian` command-line tool: `report`, `eval`, `tables`, `render`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use steradian_harness::{eval, generate, report, scene};

#[derive(Parser)]
#[command(
    name = "steradian",
    version,
    about = "Fast, accurate spherical lighting integrals: report, eval, tables, render"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run every kernel on every available backend; write report.json, index.html and a summary.
    Report {
        /// Output directory.
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// Size of the throughput workloads: inputs per kernel of the top table; every
        /// section's throughput workload (queries, products, … per timed run) is scaled by
        /// n / 2^20 (at least 1). The sections' error samples do not change with it; the top
        /// table's errors are over its first min(n, error-rows) inputs.
        #[arg(long, default_value_t = 1 << 20)]
        n: usize,
        /// Timed runs of every throughput measurement, top table and sections alike, after
        /// an untimed warm-up of at least 30 ms (the median is reported).
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Rows compared against the f64 reference (hard cases first).
        #[arg(long, default_value_t = 1 << 16)]
        error_rows: usize,
        /// Skip the wgpu backend.
        #[arg(long)]
        no_gpu: bool,
        /// Run only the section with this id (its key in report.json: lobe-product, sat,
        /// brdf_sat, lobe-sum, vdt, rsl, shade, sh), not the top table.
        #[arg(long)]
        section: Option<String>,
    },
    /// Evaluate a kernel on JSON Lines from stdin, one JSON line out per line in.
    #[command(after_help = eval::help())]
    Eval {
        /// Kernel name (see below).
        kernel: String,
    },
    /// Regenerate the precomputed tables (core/src/*/tables) and the generated SH code
    /// (core/src/sh/fixed.rs, simd/src/sh/fixed.rs).
    Tables {
        /// Do not write: fail if the committed tables differ from a fresh generation.
        #[arg(long)]
        check: bool,
        /// Root of the tree the files are written under (default: this source tree).
        #[arg(long)]
        dir: Option<PathBuf>,
    },
    /// Render a scene (a JSON file or builtin:NAME) with one method; write DIR/M.exr,
    /// DIR/M.png and DIR/M.json, and compare with DIR/path.exr when it exists.
    Render {
        /// Scene file, or builtin:lobes, builtin:cluster, builtin:environment, builtin:room.
        scene: String,
        /// Method: path (the reference), lobes, hvl or rsl.
        #[arg(long, default_value = "path")]
        method: String,
        /// Output directory.
        #[arg(long, default_value = "render")]
        out: PathBuf,
        /// Samples per pixel (path).
        #[arg(long, default_value_t = 64)]
        spp: u32,
        /// Indirect bounces (path; 0 is direct lighting).
        #[arg(long, default_value_t = 0)]
        bounces: u32,
        /// The error the approximations plan for: mean |difference| over the maximum
        /// radiance.
        #[arg(long, default_value_t = scene::render::DEFAULT_TARGET_ERROR)]
        target_error: f64,
        /// Exposure of the PNG in EV (the PNG is srgb(radiance·2^EV)).
        #[arg(long, default_value_t = 0.0)]
        exposure: f64,
        /// Override the scene's image width (the height follows the aspect ratio).
        #[arg(long)]
        width: Option<u32>,
        /// Seed of the path tracer's sample streams.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Shade with the scalar kernels (otherwise rsl and lobes shade eight points at a
        /// time with SIMD kernels, and hvl sums each receiver's HVLs with them).
        #[arg(long)]
        scalar: bool,
        /// Shade on the wgpu backend (lobes and rsl; hvl its direct and diffuse indirect light; an error without an adapter).
        #[arg(long, conflicts_with = "scalar")]
        gpu: bool,
    },
}

fn render(
    spec: &str,
    width: Option<u32>,
    method: &str,
    mut o: scene::render::Options,
) -> Result<(), String> {
    o.method = scene::render::Method::parse(method)?;
    let mut s = scene::Scene::load(spec).map_err(|e| e.to_string())?;
    if let Some(w) = width {
        s.camera = s.camera.resized(w).map_err(|e| format!("--width: {e}"))?;
    }
    let plan = scene::render::plan(&s, &o)?;
    eprintln!("plan ({}):", o.method.name());
    for p in &plan.items {
        eprintln!("  {} = {}: {}", p.item, p.value, p.reason);
    }
    let out = scene::render::run(&s, spec, &o, &plan)?;
    eprintln!(
        "{}: {}×{} in {:.2} s, written to {}",
        o.method.name(),
        s.camera.width,
        s.camera.height,
        out.seconds,
        o.out.display()
    );
    if let Some(m) = &out.metrics {
        eprintln!(
            "against path.exr: mean |diff| {:.3e} of max {:.3}, rel L2 {:.3e}, RMSE {:.4}, PSNR {:.1} dB, SSIM {:.4}; reference noise {:.2e}",
            m.mean_abs_over_max,
            m.max_radiance,
            m.rel_l2,
            m.rmse,
            m.psnr_db,
            m.ssim,
            m.reference_noise_over_max
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Render {
            scene: spec,
            method,
            out,
            spp,
            bounces,
            target_error,
            exposure,
            width,
            seed,
            quiet,
            scalar,
            gpu,
        } => {
            let o = scene::render::Options {
                method: scene::render::Method::Path,
                out,
                spp,
                bounces,
                target_error,
                exposure,
                seed,
                quiet,
                scalar,
                gpu,
            };
            match render(&spec, width, &method, o) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Report {
            out,
            n,
            repeats,
            error_rows,
            no_gpu,
            section,
        } => {
            let opts = report::Options {
                out,
                n,
                repeats,
                error_rows,
                gpu: !no_gpu,
                only: section,
            };
            match report::run(&opts) {
                Ok(r) => {
                    print!("{}", report::summary(&r));
                    println!(
                        "wrote {} and {}",
                        opts.out.join("index.html").display(),
                        opts.out.join("report.json").display()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("steradian report: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Eval { kernel } => {
            if !eval::accepts(&kernel) {
                eprintln!(
                    "steradian eval: unknown kernel {kernel:?}\n{}",
                    eval::help()
                );
                return ExitCode::from(2);
            }
            let stdin = std::io::stdin().lock();
            let stdout = std::io::stdout().lock();
            match eval::run(&kernel, stdin, stdout) {
                Ok(0) => ExitCode::SUCCESS,
                Ok(_) => ExitCode::FAILURE,
                Err(e) => {
                    eprintln!("steradian eval: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Tables { check, dir } => {
            let dir = dir.unwrap_or_else(generate::default_dir);
            match generate::run(&dir, check) {
                Ok(outcomes) => {
                    let mut ok = true;
                    for o in outcomes {
                        let what = match (check, o.matches) {
                            (false, _) => "written",
                            (true, true) => "matches a fresh generation",
                            (true, false) => "DIFFERS from a fresh generation",
                        };
                        ok &= o.matches;
                        println!("{:<40} {:>8} bytes  {what}", o.file, o.bytes);
                    }
                    if ok {
                        ExitCode::SUCCESS
                    } else {
                        eprintln!("run `steradian tables` to regenerate, then commit the tables");
                        ExitCode::FAILURE
                    }
                }
                Err(e) => {
                    eprintln!("steradian tables: {}: {e}", dir.display());
                    ExitCode::FAILURE
                }
            }
        }
    }
}
