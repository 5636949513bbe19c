//! `rtis bench`: speed figures, printed, never asserted.

use super::{CliError, runnable};
use clap::Args;
use glam::{Vec3, Vec3A};
use rtis::RenderScene;
use rtis::accel::block::Block;
use rtis::accel::{Attrs, Geometry, Isa, Prim};
use rtis::converge::{reference_shader, with_settings};
use rtis::geometry::Ray;
use rtis::mesh::displaced_sphere;
use rtis::render::render;
use rtis::sampling::{Sampler, hemisphere};
use rtis::scene::load_default;
use rtis::shader::{Global, Shader};
use std::time::Instant;

/// Arguments of `rtis bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Renders per case, at least 1; the median is printed.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    runs: u32,
    /// Divide the film size by this, from 1 (the course's 720x576) to 288 (2x2), in every
    /// section that renders (cornell and effects).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=288))]
    shrink: u32,
    /// Which figures.
    #[arg(long, value_enum, default_value_t = Section::All)]
    section: Section,
    /// Folder of scenes (or one scene file) for the effects section.
    #[arg(long, default_value = "scenes")]
    scenes: std::path::PathBuf,
    /// Print one JSON object per line (machine-readable, for bench/readme_figures.py) instead
    /// of tables.
    #[arg(long)]
    json: bool,
    /// Mesh sizes of the meshes section, in triangles (default 10000, 100000 and 1000000).
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(8..=16_000_000))]
    triangles: Vec<u32>,
    /// Write each mesh and its ray sets to this folder as raw little-endian arrays, for
    /// another engine to trace the same work (bench/embree_compare.py): `mesh-N.vertices.f32`
    /// (x y z per vertex), `mesh-N.faces.u32` (three indices per triangle),
    /// `mesh-N.coherent.f32` and `mesh-N.incoherent.f32` (ox oy oz dx dy dz per ray).
    #[arg(long)]
    dump: Option<std::path::PathBuf>,
    /// Instruction set of the meshes section's BVH node test: the widest this CPU runs
    /// (auto), one named, or each this CPU runs (one row each, their passes taking turns), to
    /// measure what it is worth. The answers are the same in each.
    #[arg(long, value_enum, default_value_t = IsaArg::Auto)]
    isa: IsaArg,
}

/// `--isa`: the node test's instruction set (the meshes section measures only the BVH).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum IsaArg {
    /// The widest this CPU runs.
    Auto,
    /// Two four-lane SSE2 halves (any x86-64 CPU).
    Baseline,
    /// One eight-lane AVX2 register.
    Avx2,
    /// AVX2's node test; sixteen AVX-512 lanes for batched rays.
    Avx512,
    /// Every one this CPU runs, baseline first.
    Each,
}

impl IsaArg {
    /// The node tests meant (AVX-512's is AVX2's, so `each` measures it once), or an error if
    /// this CPU does not run the instruction set named.
    fn isas(self) -> Result<Vec<Isa>, CliError> {
        let isa = match self {
            IsaArg::Auto => return Ok(vec![Isa::detect().node_test()]),
            IsaArg::Each => {
                let mut each: Vec<Isa> = Isa::all_available()
                    .into_iter()
                    .map(Isa::node_test)
                    .collect();
                each.dedup();
                return Ok(each);
            }
            IsaArg::Baseline => Isa::Baseline,
            IsaArg::Avx2 => Isa::Avx2,
            IsaArg::Avx512 => Isa::Avx512,
        };
        runnable(isa).map(|isa| vec![isa.node_test()])
    }
}

/// One figure of the bench: a table row, or with `--json` a JSON line.
fn emit(json: bool, row: serde_json::Value, table: impl FnOnce() -> String) {
    if json {
        println!("{row}");
    } else {
        println!("{}", table());
    }
}

/// The sections of `rtis bench`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Section {
    /// Every section below.
    All,
    /// The course's Cornell box under each shader, and cost against resolution and samples.
    Cornell,
    /// The time and error each effect costs, for every scene in --scenes.
    Effects,
    /// BVH build time, bytes per triangle and ray rates for meshes of 10k to 1M triangles.
    Meshes,
}

fn median_seconds(scene: &RenderScene, runs: u32) -> (f64, rtis::stats::RayStats) {
    let mut results: Vec<_> = (0..runs.max(1)).map(|_| render(scene, &|| {})).collect();
    results.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
    let r = &results[results.len() / 2];
    (r.seconds, r.stats)
}

/// What each effect costs: for every scene in `dir` at 360 pixels wide, the render with the
/// effects the scene calls for, then with each of them switched off in turn: seconds, rays,
/// and the error (RMSE) the saving brings.
fn effects_section(
    dir: &std::path::Path,
    runs: u32,
    shrink: u32,
    json: bool,
) -> Result<(), CliError> {
    let width = (360 / shrink).max(1);
    if !json {
        println!(
            "-- effects: the price of each effect, {width} px wide, median of {runs}: time and \
             rays with it, and with it switched off (RMSE against the full render)"
        );
        println!(
            "{:<26} {:<12} {:>9} {:>10} {:>7} {:>9}",
            "scene", "effect off", "seconds", "Mrays", "speedup", "RMSE"
        );
    }
    // A folder of scenes, or one scene file.
    let mut paths: Vec<_> = if dir.is_file() {
        vec![dir.to_path_buf()]
    } else {
        std::fs::read_dir(dir)
            .map_err(|e| format!("{}: {e}", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "ron"))
            .collect()
    };
    paths.sort();
    for path in paths {
        let mut scene = rtis::import::load_scene(&path)?;
        let f = &mut scene.settings.film;
        f.height = ((width as f64 * f.height as f64 / f.width as f64).round() as u32).max(1);
        f.width = width;
        let full = rtis::extract(&scene);
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let (t_full, s_full) = median_seconds(&full, runs);
        let reference = render(&full, &|| {}).image;
        let row = |off: &str, t: f64, rays: u64, rmse: f64| {
            serde_json::json!({
                "section": "effects", "scene": name, "width": full.film.width,
                "height": full.film.height, "effect_off": off, "seconds": t, "rays": rays,
                "speedup": t_full / t.max(1e-9), "rmse": rmse,
            })
        };
        emit(json, row("", t_full, s_full.total(), 0.0), || {
            format!(
                "{name:<26} {:<12} {t_full:>9.3} {:>10.2} {:>7} {:>9}",
                "(none)",
                s_full.total() as f64 / 1e6,
                "",
                ""
            )
        });
        for (effect, on) in full
            .effects
            .named()
            .into_iter()
            .take(rtis::converge::TRANSPORT_EFFECTS)
        {
            if !on {
                continue;
            }
            let off = rtis::converge::effect_off(&full, effect);
            let (t, st) = median_seconds(&off, runs);
            let img = render(&off, &|| {}).image;
            let rmse = rtis::converge::metrics::rmse(&img, &reference);
            emit(json, row(effect, t, st.total(), rmse), || {
                format!(
                    "{:<26} {effect:<12} {t:>9.3} {:>10.2} {:>7.2} {rmse:>9.5}",
                    "",
                    st.total() as f64 / 1e6,
                    t_full / t.max(1e-9),
                )
            });
        }
    }
    Ok(())
}

/// The CPU's model name (Linux's /proc/cpuinfo; "unknown CPU" elsewhere).
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

/// A field of /proc/self/status in MiB (Linux; 0 elsewhere).
fn status_mib(field: &str) -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(field))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// Memory one case adds at its peak, in MiB: the process's peak resident set is reset to its
/// current size (Linux's `clear_refs` 5), the case runs, and the new peak less the size before
/// it is the case's own (0 where Linux's counters are missing).
fn own_peak_mib(f: impl FnOnce()) -> f64 {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
    let before = status_mib("VmRSS:");
    f();
    (status_mib("VmHWM:") - before).max(0.0)
}

fn case(name: &str, scene: &RenderScene, runs: u32, json: bool) {
    let mut result = None;
    let peak = own_peak_mib(|| result = Some(median_seconds(scene, runs)));
    let (seconds, stats) = result.expect("the case ran");
    let (f, rays) = (scene.film, stats.total());
    let mrays = rays as f64 / seconds.max(1e-9) / 1e6;
    let row = serde_json::json!({
        "section": "cornell", "case": name, "width": f.width, "height": f.height,
        "spp": f.spp, "seconds": seconds, "rays": rays, "mrays_per_second": mrays,
        "own_peak_mib": peak,
    });
    emit(json, row, || {
        format!(
            "{name:<34} {:>4}x{:<4} {:>5} spp {seconds:>9.3} s {:>8.1} Mrays {mrays:>7.1} Mrays/s \
             {peak:>8.1} MiB own peak",
            f.width,
            f.height,
            f.spp,
            rays as f64 / 1e6,
        )
    });
}

/// Mrays/s and hits of `query` over `rays` (in parallel, chunks of 4096 rays) on the BVH in
/// each of `isas`, each the median of `runs` passes ([`rates_by`]).
fn rates(
    g: &mut Geometry,
    isas: &[Isa],
    rays: &[Ray],
    runs: u32,
    query: impl Fn(&Geometry, &Ray) -> bool + Sync + Copy,
) -> Vec<(f64, usize)> {
    use rayon::prelude::*;
    rates_by(g, isas, rays, runs, |g, rays| {
        rays.par_chunks(4096)
            .map(|c| c.iter().filter(|r| query(g, r)).count())
            .sum()
    })
}

/// [`rates`] of nearest-hit queries made in batches of consecutive rays
/// ([`Geometry::intersect_coherent`]).
fn rates_in_batches(g: &mut Geometry, isas: &[Isa], rays: &[Ray], runs: u32) -> Vec<(f64, usize)> {
    use rayon::prelude::*;
    rates_by(g, isas, rays, runs, |g, rays| {
        rays.par_chunks(4096)
            .map_init(Vec::new, |out, c| {
                g.intersect_coherent(c, out);
                out.iter().filter(|h| h.is_some()).count()
            })
            .sum()
    })
}

/// Mrays/s and hits of `pass` (which traces all of `rays` and counts the hits) on the BVH in
/// each of `isas`, each the median of `runs` passes. The instruction sets' passes take turns,
/// in reverse order every other round, so that the machine's drift falls on all of them; every
/// pass must find the same hits.
fn rates_by(
    g: &mut Geometry,
    isas: &[Isa],
    rays: &[Ray],
    runs: u32,
    pass: impl Fn(&Geometry, &[Ray]) -> usize,
) -> Vec<(f64, usize)> {
    let mut passes: Vec<Vec<(f64, usize)>> = vec![Vec::new(); isas.len()];
    for round in 0..runs.max(1) {
        let mut order: Vec<usize> = (0..isas.len()).collect();
        if round % 2 == 1 {
            order.reverse();
        }
        for k in order {
            assert!(g.bvh.set_isa(isas[k]), "checked by IsaArg::isas");
            let start = Instant::now();
            let hits = pass(g, rays);
            passes[k].push((start.elapsed().as_secs_f64(), hits));
        }
    }
    let out: Vec<(f64, usize)> = passes
        .into_iter()
        .map(|p| {
            let (seconds, hits) = median(p);
            (rays.len() as f64 / seconds / 1e6, hits)
        })
        .collect();
    assert!(
        out.iter().all(|r| r.1 == out[0].1),
        "the instruction sets found different hits"
    );
    out
}

/// The median time of `runs` (at least 1) calls of `f`, which return a time and a result that
/// every call must agree on.
fn median_of<T: PartialEq + std::fmt::Debug>(
    runs: u32,
    mut f: impl FnMut() -> (f64, T),
) -> (f64, T) {
    median((0..runs.max(1)).map(|_| f()).collect())
}

/// The result of median time among `results` (at least one), which must all agree.
fn median<T: PartialEq + std::fmt::Debug>(mut results: Vec<(f64, T)>) -> (f64, T) {
    results.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mid = results.swap_remove(results.len() / 2);
    assert!(results.iter().all(|r| r.1 == mid.1), "runs disagree");
    mid
}

/// A built geometry, compared by its node count (builds of the same primitives agree).
struct BuiltOnce(Geometry);

impl PartialEq for BuiltOnce {
    fn eq(&self, other: &Self) -> bool {
        self.0.bvh.node_count() == other.0.bvh.node_count()
    }
}

impl std::fmt::Debug for BuiltOnce {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{} wide nodes", self.0.bvh.node_count())
    }
}

/// BVH build time, memory per triangle and ray rates for procedural meshes of 10k, 100k and
/// 1M triangles (a displaced sphere of radius 1 at the origin).
fn meshes_section(
    json: bool,
    isas: &[Isa],
    runs: u32,
    sizes: &[u32],
    dump: Option<&std::path::Path>,
) -> Result<(), CliError> {
    if !json {
        println!("-- meshes: displaced sphere, 1M rays of each kind");
        println!(
            "{:>9} {:>9} {:>8} {:>9} {:>10} {:>11} {:>11} {:>13} {:>9}",
            "triangles",
            "build s",
            "nodes",
            "BVH B/tri",
            "attr B/tri",
            "camera",
            "shadow",
            "incoherent",
            "node test"
        );
    }
    let sizes = if sizes.is_empty() {
        &[10_000, 100_000, 1_000_000][..]
    } else {
        sizes
    };
    // Warm-up: a throw-away build big enough to run in parallel, so that rayon's workers exist
    // before the first measured build (as bench/embree_compare.py warms Embree's TBB workers
    // with a throw-away scene of 30,000 triangles).
    drop(Geometry::build(
        Prim::flat_triangles(&displaced_sphere(30_000, Vec3::ZERO, 1.0, 0.05)),
        Vec::new(),
    ));
    for &n in sizes {
        let mesh = displaced_sphere(n as usize, Vec3::ZERO, 1.0, 0.05);
        let prims = Prim::flat_triangles(&mesh);
        let count = prims.len();
        // The median of `runs` builds. `median_of` keeps every build until the last is done, so
        // each writes fresh memory as the first does (and as `bench/embree_compare.py` measures
        // Embree's builds) instead of pages a dropped build left warm.
        let (build, g) = median_of(runs, || {
            let prims = prims.clone();
            let start = Instant::now();
            let g = Geometry::build(prims, Vec::new());
            (start.elapsed().as_secs_f64(), BuiltOnce(g))
        });
        let mut g = g.0;
        let nodes = g.bvh.node_count();
        // The tree's nodes of both kinds and its leaves' blocks of lanes.
        let bvh_bytes = (g.bvh.node_bytes() + g.blocks.len() * std::mem::size_of::<Block>()) as f64
            / count as f64;
        // Camera rays: a pinhole at z = -3 through a 1000 x 1000 grid covering the sphere.
        let eye = Vec3A::new(0.0, 0.0, -3.0);
        let camera: Vec<Ray> = (0..1_000_000)
            .map(|i| {
                let (x, y) = (
                    (i % 1000) as f32 / 500.0 - 1.0,
                    (i / 1000) as f32 / 500.0 - 1.0,
                );
                Ray::new(eye, (Vec3A::new(1.2 * x, 1.2 * y, 3.0)).normalize())
            })
            .collect();
        let closest = |g: &Geometry, r: &Ray| g.intersect(r).is_some();
        // Camera rays go in packets ([`Geometry::intersect_coherent`]), as a renderer hands
        // over a tile's rays together.
        let camera_rates = rates_in_batches(&mut g, isas, &camera, runs);
        // Shadow rays from the visible surface towards a light at (2, 3, -3).
        let light = Vec3A::new(2.0, 3.0, -3.0);
        let shadow: Vec<Ray> = camera
            .iter()
            .filter_map(|r| g.intersect(r))
            .map(|h| {
                let to = light - h.p;
                let w = to.normalize();
                Ray::spawn(&h, w, to.length() * 0.9999)
            })
            .collect();
        let shadow_rates = rates(&mut g, isas, &shadow, runs, |g, r| g.occluded(r));
        // Incoherent rays: random origins in the box [-2, 2]^3, random directions.
        let mut s = Sampler::new(1, 2, 3);
        let incoherent: Vec<Ray> = (0..1_000_000)
            .map(|_| {
                let o =
                    Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 4.0 - Vec3A::splat(2.0);
                let (u, v) = s.next_2d();
                let mut d = hemisphere::uniform(u, v);
                if s.next_f32() < 0.5 {
                    d.z = -d.z;
                }
                Ray::new(o, d)
            })
            .collect();
        let incoherent_rates = rates(&mut g, isas, &incoherent, runs, closest);
        // The same rays split into those that hit and those that miss, each set traced apart:
        // a hit costs the leaf tests and the record, a miss mostly the top of the tree, so
        // the two rates show where a gap to another engine lies.
        let (inc_hit, inc_miss): (Vec<Ray>, Vec<Ray>) =
            incoherent.iter().partition(|r| g.intersect(r).is_some());
        let hit_rates = rates(&mut g, isas, &inc_hit, runs, closest);
        let miss_rates = rates(&mut g, isas, &inc_miss, runs, closest);
        // What shading needs besides the vertices: each lane's material, normals and light
        // (and whole primitives for shapes outside the blocks: none here).
        let prim_bytes = (g.attrs.len() * std::mem::size_of::<Attrs>()
            + g.others.len() * std::mem::size_of::<Prim>()) as f64
            / count as f64;
        if let Some(dir) = dump {
            dump_work(dir, n, &mesh, &camera, &incoherent)?;
        }
        for (k, isa) in isas.iter().map(|i| i.name()).enumerate() {
            let ((cam_rate, cam_hits), (shadow_rate, _), (inc_rate, inc_hits)) =
                (camera_rates[k], shadow_rates[k], incoherent_rates[k]);
            let (inc_hit_rate, inc_miss_rate) = (hit_rates[k].0, miss_rates[k].0);
            let row = serde_json::json!({
                "section": "meshes", "engine": "rtis", "isa": isa, "triangles": count,
                "build_s": build,
                "nodes": nodes, "threads": rayon::current_num_threads(),
                "bvh_bytes_per_triangle": bvh_bytes, "attribute_bytes_per_triangle": prim_bytes,
                "bytes_per_triangle": bvh_bytes + prim_bytes,
                "camera_mrays": cam_rate, "coherent_mrays": cam_rate, "shadow_mrays": shadow_rate,
                "incoherent_mrays": inc_rate, "coherent_hits": cam_hits,
                "incoherent_hit_mrays": inc_hit_rate, "incoherent_miss_mrays": inc_miss_rate,
                "incoherent_hits": inc_hits,
            });
            emit(json, row, || {
                format!(
                    "{count:>9} {build:>9.3} {nodes:>8} {bvh_bytes:>9.1} {prim_bytes:>10.1} \
                     {cam_rate:>7.1} M/s {shadow_rate:>7.1} M/s {inc_rate:>9.1} M/s {isa:>9}"
                )
            });
        }
    }
    Ok(())
}

/// Write a mesh and its ray sets as raw little-endian arrays (see `BenchArgs::dump`), each
/// through a temporary file.
fn dump_work(
    dir: &std::path::Path,
    n: u32,
    mesh: &rtis::mesh::MeshData,
    coherent: &[Ray],
    incoherent: &[Ray],
) -> Result<(), CliError> {
    let write = |name: String, floats: Vec<[u8; 4]>| -> Result<(), CliError> {
        let bytes: Vec<u8> = floats.concat();
        let path = dir.join(name);
        rtis::render::output::write_file(&path, &bytes)?;
        Ok(())
    };
    let f = |v: f32| v.to_le_bytes();
    write(
        format!("mesh-{n}.vertices.f32"),
        mesh.positions
            .iter()
            .flat_map(|p| p.as_vec3().to_array().map(f))
            .collect(),
    )?;
    write(
        format!("mesh-{n}.faces.u32"),
        mesh.faces
            .iter()
            .flat_map(|t| t.map(|i| i.to_le_bytes()))
            .collect(),
    )?;
    let rays = |rs: &[Ray]| -> Vec<[u8; 4]> {
        rs.iter()
            .flat_map(|r| [r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z].map(f))
            .collect()
    };
    write(format!("mesh-{n}.coherent.f32"), rays(coherent))?;
    write(format!("mesh-{n}.incoherent.f32"), rays(incoherent))
}

/// Run `rtis bench`.
pub fn run(a: BenchArgs) -> Result<(), CliError> {
    // Refused before any figure, whichever sections run.
    let isas = a.isa.isas()?;
    let threads = rayon::current_num_threads();
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let head = serde_json::json!({
        "section": "machine", "cores": cores, "threads": threads, "runs": a.runs,
        "cpu": cpu_model(),
    });
    emit(a.json, head, || {
        format!(
            "rtis bench: {} ({cores} cores available), {threads} threads, median of {} runs",
            cpu_model(),
            a.runs
        )
    });
    let wants = |s: Section| a.section == Section::All || a.section == s;
    if wants(Section::Meshes) {
        meshes_section(a.json, &isas, a.runs, &a.triangles, a.dump.as_deref())?;
    }
    if wants(Section::Effects) {
        effects_section(&a.scenes, a.runs, a.shrink, a.json)?;
    }
    if !wants(Section::Cornell) {
        return Ok(());
    }
    let mut scene = load_default();
    scene.settings.film.width /= a.shrink;
    scene.settings.film.height /= a.shrink;
    let base = rtis::extract(&scene);
    let global = |samples, max_depth| {
        Shader::Global(Global {
            samples,
            max_depth,
            ambient: glam::Vec3A::splat(0.3),
            max_specular: 32,
            light_samples: 1,
        })
    };
    if !a.json {
        println!("-- the course's Cornell box");
    }
    case(
        "Direct",
        &with_settings(
            &base,
            Shader::Direct {
                max_specular: 32,
                light_samples: 1,
            },
            1,
        ),
        a.runs,
        a.json,
    );
    case(
        "Global n=64 D=3",
        &with_settings(&base, global(64, 3), 1),
        a.runs,
        a.json,
    );
    case(
        "Path (Course model) 64 spp",
        &with_settings(&base, reference_shader(), 64),
        a.runs,
        a.json,
    );
    let mut physical = with_settings(&base, reference_shader(), 64);
    physical.model = rtis::scene::Model::Physical;
    case("Path (Physical model) 64 spp", &physical, a.runs, a.json);
    if !a.json {
        println!("-- cost against resolution and samples (Global n=16 D=2; should grow linearly)");
    }
    for (div, spp) in [(2, 1), (1, 1), (2, 4), (1, 4)] {
        let mut s = with_settings(&base, global(16, 2), spp);
        s.film.width /= div;
        s.film.height /= div;
        case("Global n=16 D=2", &s, a.runs, a.json);
    }
    Ok(())
}
