//! `penumbra`: bake a scene JSON file into a bake JSON file.
//!
//! Exit codes: 0 success, 2 invalid input (one line on stderr naming the object and field),
//! 1 I/O failure writing the output, 3 internal error (a bug: reported in one line, no trace).

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use clap::{Parser, Subcommand};
use penumbra::{BakeError, Progress};

#[derive(Parser)]
#[command(
    name = "penumbra",
    version,
    about = "Discontinuity-meshing radiosity baker"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Bake SCENE (scene JSON, `-` for stdin) and write the bake JSON.
    Bake {
        scene: PathBuf,
        /// Output file: bake JSON, or binary glTF when it ends in `.glb`; `-` for stdout (JSON).
        #[arg(short, long)]
        output: PathBuf,
        /// Print the stats table (paper's names) to stderr when done.
        #[arg(long)]
        stats: bool,
        /// Worker threads, 1 to 1024 like the `threads` setting (default: all cores).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=penumbra_cli::args::MAX_THREADS))]
        threads: Option<u32>,
        /// Relative error of the baked direct light (like the `tolerance` setting, which it
        /// overrides): 0.03 draft, 0.01 medium (default), 0.003 high.
        #[arg(long)]
        tolerance: Option<f64>,
        /// Also rasterise each mesh that has `uv` into a RES×RES lightmap
        /// (`<name>_radiosity.exr`, float RGB, linear); overrides settings.lightmap_resolution.
        #[arg(long, value_name = "RES")]
        lightmap: Option<i64>,
        /// Rings of texels filled around the UV islands (default 16).
        #[arg(long)]
        margin: Option<i64>,
        /// Where lightmaps go (default: beside the output file).
        #[arg(long, value_name = "DIR")]
        lightmap_dir: Option<PathBuf>,
        /// Most memory the bake may need by the resource model's estimate, like the
        /// `max_memory` setting: bytes or 8G, 512M (default: half the machine's memory).
        #[arg(long, value_name = "SIZE", value_parser = penumbra_cli::args::parse_size)]
        max_memory: Option<u64>,
    },
    /// Check SCENE and report problems without baking.
    Validate { scene: PathBuf },
    /// Write a built-in scene (data1, data2, chair, cornell, room) as scene JSON.
    Scene {
        name: String,
        #[arg(short, long)]
        output: PathBuf,
    },
}

fn read(path: &PathBuf) -> Result<String, String> {
    if path.as_os_str() == "-" {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut std::io::stdin(), &mut s)
            .map_err(|e| format!("stdin: {e}"))?;
        Ok(s)
    } else {
        std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))
    }
}

fn fail(code: u8, msg: impl std::fmt::Display) -> ExitCode {
    eprintln!("penumbra: {msg}");
    ExitCode::from(code)
}

fn main() -> ExitCode {
    // A bug must still end in one line, not a backtrace.
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!("penumbra: internal error: {msg}{at}");
    }));
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => return penumbra_cli::args::report(e),
    };
    match std::panic::catch_unwind(|| run(cli)) {
        Ok(code) => code,
        Err(_) => ExitCode::from(3),
    }
}

fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Scene { name, output } => {
            let Some(s) = penumbra::scenes::by_name(&name) else {
                return fail(
                    2,
                    format!(
                        "unknown scene {name:?} (one of {})",
                        penumbra::scenes::NAMES.join(", ")
                    ),
                );
            };
            let json = serde_json::to_string_pretty(&s).expect("scene serialises");
            match std::fs::write(&output, json) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => fail(1, format!("{}: {e}", output.display())),
            }
        }
        Command::Validate { scene } => {
            let text = match read(&scene) {
                Ok(t) => t,
                Err(e) => return fail(2, e),
            };
            match penumbra::SceneJson::from_str(&text).and_then(|j| penumbra::scene::validate(&j)) {
                Ok(s) => {
                    for w in &s.warnings {
                        eprintln!("penumbra: warning: {w}");
                    }
                    let emitters = s.lights.iter().filter(|l| l.from_face.is_some()).count();
                    println!(
                        "ok: {} meshes, {} convex faces, {} lights ({emitters} of them from emissive faces)",
                        s.meshes.len(),
                        s.faces.len(),
                        s.lights.len()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => fail(2, e),
            }
        }
        Command::Bake {
            scene,
            output,
            stats,
            threads,
            tolerance,
            lightmap,
            margin,
            lightmap_dir,
            max_memory,
        } => {
            let text = match read(&scene) {
                Ok(t) => t,
                Err(e) => return fail(2, e),
            };
            let mut json = match penumbra::SceneJson::from_str(&text) {
                Ok(j) => j,
                Err(e) => return fail(2, e),
            };
            if lightmap.is_some() {
                json.settings.lightmap_resolution = lightmap;
            }
            if margin.is_some() {
                json.settings.lightmap_margin = margin;
            }
            if max_memory.is_some() {
                json.settings.max_memory = max_memory;
            }
            if tolerance.is_some() {
                json.settings.tolerance = tolerance;
            }
            // Bad lightmap settings or UVs fail before the bake, not after it.
            if let Err(e) = check_lightmaps(&json) {
                return fail(2, e);
            }
            let mut sc = match penumbra::scene::validate(&json) {
                Ok(s) => s,
                Err(e) => return fail(2, e),
            };
            if let Some(t) = threads {
                sc.settings.threads = Some(t);
            }
            for w in &sc.warnings {
                eprintln!("penumbra: warning: {w}");
            }
            let progress = Arc::new(Progress::new());
            let bar = std::io::stderr()
                .is_terminal()
                .then(|| spawn_bar(progress.clone()));
            let result = penumbra::bake(&sc, &progress);
            progress.cancel(); // stops the bar thread
            if let Some(h) = bar {
                let _ = h.join();
            }
            let bake = match result {
                Ok(b) => b,
                Err(e @ BakeError::Cancelled) => return fail(1, e),
                Err(e) => return fail(2, e),
            };
            let glb = output
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
            let written = if output.as_os_str() == "-" {
                penumbra_cli::args::write_stdout(&bake.to_json())
            } else if glb {
                std::fs::write(&output, penumbra_cli::gltf::to_glb(&bake))
            } else {
                std::fs::File::create(&output).and_then(|f| bake.write_json(f))
            };
            match written {
                Ok(()) => {}
                // The reader went away (`| head`): nothing more to say, and nobody to say it to.
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return ExitCode::from(1),
                Err(e) => return fail(1, format!("{}: {e}", output.display())),
            }
            if stats {
                eprint!("{}", penumbra::bake::stats_table(&bake.stats));
            }
            let dir = lightmap_dir
                .unwrap_or_else(|| output.parent().map(|p| p.to_path_buf()).unwrap_or_default());
            write_lightmaps(&json, &bake, &dir)
        }
    }
}

fn check_lightmaps(json: &penumbra::SceneJson) -> Result<(), BakeError> {
    if penumbra::lightmap::LightmapSettings::from_json(&json.settings)?.is_none() {
        return Ok(());
    }
    for (mi, m) in json.meshes.iter().enumerate() {
        let Some(uvs) = &m.uv else { continue };
        let obj = format!("mesh {:?} (meshes[{mi}])", m.name);
        let (starts, corners) = penumbra::lightmap::flat_polygons(&m.polygons, m.positions.len())
            .map_err(|(k, i)| {
            BakeError::invalid(
                &obj,
                format!("polygons[{k}]"),
                format!("index {i} is out of range"),
            )
        })?;
        let layout = penumbra::lightmap::UvLayout {
            positions: &m.positions,
            starts: &starts,
            corners: &corners,
            uvs,
        };
        penumbra::lightmap::check_uv(&obj, &layout)?;
    }
    Ok(())
}

fn write_lightmaps(
    json: &penumbra::SceneJson,
    bake: &penumbra::Bake,
    dir: &std::path::Path,
) -> ExitCode {
    let maps = match penumbra::lightmap::scene_lightmaps(json, bake, &Progress::new()) {
        Ok(m) => m,
        Err(e) => return fail(2, e),
    };
    if maps.iter().any(Option::is_some) {
        if let Err(e) = std::fs::create_dir_all(dir) {
            return fail(1, format!("{}: {e}", dir.display()));
        }
    }
    for (m, lm) in json.meshes.iter().zip(&maps) {
        if let Some(lm) = lm {
            let path = penumbra_cli::images::lightmap_path(dir, &m.name);
            if let Err(e) = penumbra_cli::images::write_exr(&path, lm) {
                return fail(1, e);
            }
        }
    }
    ExitCode::SUCCESS
}

fn spawn_bar(p: Arc<Progress>) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let bar = indicatif::ProgressBar::new(1000);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {msg:24} [{bar:40}] {percent:>3}%")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        while !p.is_cancelled() {
            let (stage, f) = p.get();
            bar.set_message(stage);
            bar.set_position((f * 1000.0) as u64);
            std::thread::sleep(Duration::from_millis(100));
        }
        bar.finish_and_clear();
    })
}

#[cfg(not(target_env = "msvc"))]
#[global_allocator]
static GLOBAL: tikv_jemallocator::Jemalloc = tikv_jemallocator::Jemalloc;
