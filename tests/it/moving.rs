//! Moving contact surfaces (`[displacement]`): a gap closing in time under a gas-gap
//! conductance gives the heat history of the gap law, the searches follow `Update
//! Search Every n Steps`, a displacement read from an Exodus result moves the surfaces
//! as the same displacement written as Lua, and what cannot move is refused.

use std::path::{Path, PathBuf};

use seam::mesh::Mesh;
use seam::mesh::generate::{self, BoxSpec};
use seam::output::exodus::ExodusWriter;
use seam::run::{RunError, RunResult};

use super::embed::scratch;

/// Block 1 `[0,1]² × [0,1]` (3 × 3 × 4 hexes) and block 2 `[0,1]² × [1 + g0, 2 + g0]` (4 ×
/// 4 × 3), meshed apart. Side sets: 1 block 1's bottom, 2 its top, 3 block 2's bottom, 4
/// its top.
fn parts(g0: f64) -> Mesh {
    parts_at(g0, 0.0)
}

/// As [`parts`], block 2 shifted by `dx` along x.
fn parts_at(g0: f64, dx: f64) -> Mesh {
    generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 1.0], [3, 3, 4], 1)
                .with_side_sets([0, 0, 0, 0, 1, 2]),
            BoxSpec::hex([dx, 0.0, 1.0 + g0], [1.0 + dx, 1.0, 2.0 + g0], [4, 4, 3], 2)
                .with_side_sets([0, 0, 0, 0, 3, 4]),
        ],
        false,
    )
}

const G0: f64 = 0.1;
const K_GAS: f64 = 0.05;
/// The speed at which block 2 comes down (m/s).
const SPEED: f64 = 0.008;

/// The gap closing problem: T = 1 at z = 0, T = 0 on block 2's top, k = 1, a capacity
/// small enough that every step is steady to 1e-9, ten steps of 1 s; `extra` problem
/// lines and `every` the search schedule.
fn closing(dir: &Path, displacement: &str, every: Option<u32>) -> PathBuf {
    ExodusWriter::create(&dir.join("mesh.exo"), &parts(G0), &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"mesh.exo\"\n\
             [[material]]\nblocks = [\"block_1\", \"block_2\"]\nconductivity = 1.0\nrho_c = 1e-12\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = 1.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n\
             [initial]\ntemperature = 0.5\n\
             {displacement}\
             [contact]\nfile = \"contact.i\"\n\
             [solve]\nkind = \"transient\"\nscheme = \"backward_euler\"\ndt = 1.0\nend_time = 10.0\ntolerance = 1e-12\n"
        ),
    )
    .unwrap();
    let schedule = every.map_or(String::new(), |n| {
        format!("  update search every {n} steps\n")
    });
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n  contact surface a contains surface_2\n  contact surface b contains surface_3\n{schedule}\
             begin search options\n    normal tolerance = 0.3\n  end\n\
             begin interaction\n    side a a\n    side b b\n  end\n\
             begin enforcement\n    enforcement for energy = gap_conductance\n    gap conductance coefficient = gas_gap k = {K_GAS} min_gap = 1e-4\n  end\nend\n"
        ),
    )
    .unwrap();
    dir.join("problem.toml")
}

fn run(problem: &Path) -> RunResult {
    match seam::run::run(problem) {
        Ok(r) => r,
        Err(RunError::Input(d, s)) => panic!("{}", d.render(&s)),
        Err(RunError::Solve(e)) => panic!("{e}"),
    }
}

/// Block 2 comes down at `SPEED`: its nodes are those above z = 1 + g0/2.
const LUA_DOWN: &str = "[displacement]\nvalue = [0.0, 0.0, \"z > 1.05 and -0.008*t or 0\"]\n";

/// The series heat through a unit area at gap g: 1 / (1/k + g/k_gas + 1/k).
fn series_heat(g: f64) -> f64 {
    1.0 / (1.0 + g / K_GAS + 1.0)
}

/// The largest relative difference between each step's heat (both sides) and the gap
/// law's at that step's gap.
fn worst_against_gap_law(r: &RunResult) -> f64 {
    assert_eq!(r.history.len(), 10, "ten steps");
    let mut worst = 0.0f64;
    for s in &r.history {
        let exact = series_heat(G0 - SPEED * s.time);
        // Heat leaves side A (block 1, the hot one) and enters side B.
        let (a, b) = s.heat[0];
        let err = ((a - exact).abs()).max((-b - exact).abs()) / exact;
        println!(
            "t = {}: heat {a} / {}, gap law {exact}, rel err {err:.1e}",
            s.time, -b
        );
        worst = worst.max(err);
    }
    worst
}

#[test]
fn a_closing_gap_follows_the_gap_law_step_by_step() {
    let dir = scratch("moving-closing");
    let r = run(&closing(&dir, LUA_DOWN, None));
    let worst = worst_against_gap_law(&r);
    assert!(worst <= 1e-8, "{worst:e}");
    // Without the motion the heat stays that of the first gap: the check can fail.
    let still = run(&closing(&dir, "", None));
    let last = still.history.last().unwrap().heat[0].0;
    assert!((last - series_heat(G0)).abs() <= 1e-8 * series_heat(G0));
    assert!((last - series_heat(G0 - 10.0 * SPEED)).abs() > 0.1 * last);
    // Searched at the start and at every step (no schedule: every step).
    let m = r.summary.motion.expect("a moving run reports its searches");
    assert_eq!((m.searches, m.refits), (11, 0), "{m:?}");
    assert!(still.summary.motion.is_none());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn searches_follow_the_schedule_and_refits_keep_the_gap_law() {
    let dir = scratch("moving-schedule");
    let r = run(&closing(&dir, LUA_DOWN, Some(3)));
    // Steps 3, 6 and 9 search, besides the start; the other seven steps refit.
    let m = r.summary.motion.unwrap();
    assert_eq!((m.searches, m.refits), (4, 7), "{m:?}");
    let worst = worst_against_gap_law(&r);
    assert!(worst <= 1e-8, "{worst:e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The same motion as a structural result would give it: `DISPLX`, `DISPLY`, `DISPLZ`
/// stored at t = 0, 5 and 10 (linear in t, so interpolation is exact).
#[test]
fn a_displacement_read_from_an_exodus_result_moves_the_surfaces_as_the_lua_one() {
    let dir = scratch("moving-exodus");
    let problem = closing(&dir, LUA_DOWN, Some(2));
    let lua = run(&problem);
    let mesh = parts(G0);
    let down: Vec<bool> = mesh.coords.iter().map(|x| x[2] > 1.05).collect();
    let zeros = vec![0.0; mesh.num_nodes()];
    let mut w = ExodusWriter::create(
        &dir.join("structure.exo"),
        &mesh,
        &["DISPLX", "DISPLY", "DISPLZ"],
        &[],
    )
    .unwrap();
    for t in [0.0, 5.0, 10.0] {
        let uz: Vec<f64> = down
            .iter()
            .map(|&d| if d { -SPEED * t } else { 0.0 })
            .collect();
        w.write_step(t, &[&zeros, &zeros, &uz], &[]).unwrap();
    }
    w.finish().unwrap();
    let text = std::fs::read_to_string(&problem)
        .unwrap()
        .replace(LUA_DOWN, "[displacement]\nfile = \"structure.exo\"\n");
    std::fs::write(&problem, text).unwrap();
    let exodus = run(&problem);
    assert_eq!(lua.summary.motion, exodus.summary.motion);
    let mut worst = 0.0f64;
    for (a, b) in lua.history.iter().zip(&exodus.history) {
        worst = worst.max((a.heat[0].0 - b.heat[0].0).abs() / a.heat[0].0);
    }
    println!("Lua against Exodus displacement: heats within {worst:.1e}");
    assert!(worst <= 1e-12, "{worst:e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Block 2 slides 0.3 along x over ten steps: the searches pair side-A points with other
/// side-B faces (and leave some unpaired), the solver makes its pattern again, and the
/// last step's heat is that of a mesh built where block 2 ends up.
#[test]
fn a_sliding_part_is_searched_anew_and_ends_as_a_mesh_built_there() {
    let dir = scratch("moving-sliding");
    let slide = "[displacement]\nvalue = [\"z > 1.05 and 0.03*t or 0\", 0.0, 0.0]\n";
    let moving = run(&closing(&dir, slide, None));
    let m = moving.summary.motion.unwrap();
    assert!(m.repatterns >= 1, "{m:?}");
    let (a, b) = moving.history.last().unwrap().heat[0];
    // A mesh built where block 2 ends up, searched once.
    let problem = closing(&dir, "", None);
    ExodusWriter::create(&dir.join("mesh.exo"), &parts_at(G0, 0.3), &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    let built = run(&problem);
    let (a0, b0) = built.history.last().unwrap().heat[0];
    let diff = ((a - a0).abs()).max((b - b0).abs()) / a0;
    println!(
        "slid: heat {a} / {}, built there: {a0} / {}, rel diff {diff:.1e}; {m:?}",
        -b, -b0
    );
    // Less overlap, less heat than the full faces at that gap.
    assert!(a0 < 0.8 * series_heat(G0), "{a0}");
    assert!(diff <= 1e-9, "{diff:e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn what_cannot_move_is_refused_with_its_reason() {
    let dir = scratch("moving-refused");
    let problem = closing(&dir, LUA_DOWN, None);
    let codes = |edit: &dyn Fn(&str) -> String| -> Vec<(String, Option<u32>)> {
        let text = std::fs::read_to_string(&problem).unwrap();
        let changed = dir.join("changed.toml");
        std::fs::write(&changed, edit(&text)).unwrap();
        match seam::run::check(&changed) {
            Ok(_) => Vec::new(),
            Err(RunError::Input(d, _)) => {
                d.0.iter()
                    .filter(|d| d.severity == seam::diag::Severity::Error)
                    .map(|d| (d.code.to_string(), d.loc.as_ref().map(|l| l.line)))
                    .collect()
            }
            Err(e) => panic!("{e:?}"),
        }
    };
    assert!(codes(&|s: &str| s.to_string()).is_empty());
    let line =
        |text: &str, what: &str| text.lines().position(|l| l.starts_with(what)).unwrap() as u32 + 1;
    let text = std::fs::read_to_string(&problem).unwrap();
    let at = line(&text, "value = [0.0");
    // Two components for a 3-D mesh.
    let two = |s: &str| s.replace("value = [0.0, 0.0, ", "value = [0.0, ");
    assert_eq!(codes(&two), [("E0730".to_string(), Some(at))]);
    // Both a value and a file.
    let both = |s: &str| s.replace("[displacement]\n", "[displacement]\nfile = \"x.exo\"\n");
    assert_eq!(codes(&both)[0].0, "E0730");
    // A file that is not there names the file.
    let missing = |s: &str| {
        s.replace(
            "value = [0.0, 0.0, \"z > 1.05 and -0.008*t or 0\"]",
            "file = \"nowhere.exo\"",
        )
    };
    assert_eq!(codes(&missing)[0].0, "E0730");
    // A Lua expression that fails where the run starts.
    let bad = |s: &str| s.replace("-0.008*t", "-0.008*q");
    assert_eq!(codes(&bad), [("E0730".to_string(), Some(at))]);
    // A multiplier tie cannot move.
    let tie = |s: &str| s.to_string();
    std::fs::write(
        dir.join("contact.i"),
        std::fs::read_to_string(dir.join("contact.i")).unwrap().replace(
            "enforcement for energy = gap_conductance\n    gap conductance coefficient = gas_gap k = 0.05 min_gap = 1e-4",
            "enforcement for energy = tied multipliers = dual\n    side b variable temperature to temperature",
        ),
    )
    .unwrap();
    let refused = codes(&tie);
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert_eq!(refused[0].0, "E0731");
    std::fs::remove_dir_all(&dir).ok();
}
