//! Moving contact surfaces (`[displacement]`): a gap closing in time under a gas-gap
//! conductance gives the heat history of the gap law, the searches follow `Update
//! Search Every n Steps`, a displacement read from an Exodus result moves the surfaces
//! as the same displacement written as Lua, and what cannot move is refused.

use std::path::{Path, PathBuf};

use seam::mesh::Mesh;
use seam::mesh::generate::{self, BoxSpec};
use seam::output::exodus::ExodusWriter;
use seam::run::{RunError, RunResult};

use crate::scratch;

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
    std::fs::write(dir.join("problem.toml"), stack_problem(displacement)).unwrap();
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

/// The problem file of the two stacked blocks on `mesh.exo`: T = 1 on side set 1, T = 0
/// on side set 4, k = 1, a capacity small enough that every step is steady to 1e-9, ten
/// backward-Euler steps of 1 s, the deck `contact.i`, and `extra` tables.
fn stack_problem(extra: &str) -> String {
    format!(
        "[mesh]\nfile = \"mesh.exo\"\n\
         [[material]]\nblocks = [\"block_1\", \"block_2\"]\nconductivity = 1.0\nrho_c = 1e-12\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = 1.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n\
         [initial]\ntemperature = 0.5\n\
         {extra}\
         [contact]\nfile = \"contact.i\"\n\
         [solve]\nkind = \"transient\"\nscheme = \"backward_euler\"\ndt = 1.0\nend_time = 10.0\ntolerance = 1e-12\n"
    )
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
    let tmp = scratch("moving-closing");
    let dir = tmp.path();
    let r = run(&closing(dir, LUA_DOWN, None));
    let worst = worst_against_gap_law(&r);
    assert!(worst <= 1e-8, "{worst:e}");
    // Without the motion the heat stays that of the first gap: the check can fail.
    let still = run(&closing(dir, "", None));
    let last = still.history.last().unwrap().heat[0].0;
    assert!((last - series_heat(G0)).abs() <= 1e-8 * series_heat(G0));
    assert!((last - series_heat(G0 - 10.0 * SPEED)).abs() > 0.1 * last);
    // Searched at the start and at every step (no schedule: every step).
    let m = r.summary.motion.expect("a moving run reports its searches");
    assert_eq!((m.searches, m.refits), (11, 0), "{m:?}");
    assert!(still.summary.motion.is_none());
}

#[test]
fn searches_follow_the_schedule_and_refits_keep_the_gap_law() {
    let tmp = scratch("moving-schedule");
    let dir = tmp.path();
    let r = run(&closing(dir, LUA_DOWN, Some(3)));
    // Steps 3, 6 and 9 search, besides the start; the other seven steps refit.
    let m = r.summary.motion.unwrap();
    assert_eq!((m.searches, m.refits), (4, 7), "{m:?}");
    let worst = worst_against_gap_law(&r);
    assert!(worst <= 1e-8, "{worst:e}");
}

/// The same motion as a structural result would give it: `DISPLX`, `DISPLY`, `DISPLZ`
/// stored at t = 0, 5 and 10 (linear in t, so interpolation is exact).
#[test]
fn a_displacement_read_from_an_exodus_result_moves_the_surfaces_as_the_lua_one() {
    let tmp = scratch("moving-exodus");
    let dir = tmp.path();
    let problem = closing(dir, LUA_DOWN, Some(2));
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
}

/// Block 2 slides 0.3 along x over ten steps: the searches pair side-A points with other
/// side-B faces (and leave some unpaired), the solver makes its pattern again, and the
/// last step's heat is that of a mesh built where block 2 ends up.
#[test]
fn a_sliding_part_is_searched_anew_and_ends_as_a_mesh_built_there() {
    let tmp = scratch("moving-sliding");
    let dir = tmp.path();
    let slide = "[displacement]\nvalue = [\"z > 1.05 and 0.03*t or 0\", 0.0, 0.0]\n";
    let moving = run(&closing(dir, slide, None));
    let m = moving.summary.motion.unwrap();
    assert!(m.repatterns >= 1, "{m:?}");
    let (a, b) = moving.history.last().unwrap().heat[0];
    // A mesh built where block 2 ends up, searched once.
    let problem = closing(dir, "", None);
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
}

#[test]
fn what_cannot_move_is_refused_with_its_reason() {
    let tmp = scratch("moving-refused");
    let dir = tmp.path();
    let problem = closing(dir, LUA_DOWN, None);
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
}

/// Block 1 in two layers under the lid at gap `G0`; at t = 5 its upper layer dies. With
/// block 1 skinned for contact, the faces the death exposes at z = 0.5 join its surface
/// and carry the heat across the wider gap; with the side set of its top instead, the
/// surface loses its faces and the interaction carries nothing (the Sierra rule).
fn dying(dir: &Path, side_a: &str) -> (PathBuf, Vec<i64>) {
    let mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 1.0], [2, 2, 2], 1)
                .with_side_sets([0, 0, 0, 0, 1, 2]),
            BoxSpec::hex([0.0, 0.0, 1.0 + G0], [1.0, 1.0, 2.0 + G0], [3, 3, 2], 2)
                .with_side_sets([0, 0, 0, 0, 3, 4]),
        ],
        false,
    );
    // The upper layer of block 1, by element number.
    let upper: Vec<i64> = mesh.blocks[0]
        .elems()
        .filter(|&e| {
            let z: f64 = mesh
                .elem_nodes(e)
                .iter()
                .map(|n| mesh.coords[n.index()][2])
                .sum();
            z / 8.0 > 0.5
        })
        .map(|e| mesh.elem_numbers[e.index()])
        .collect();
    assert_eq!(upper.len(), 4);
    ExodusWriter::create(&dir.join("mesh.exo"), &mesh, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    let numbers: Vec<String> = upper.iter().map(i64::to_string).collect();
    let death = format!(
        "[[death]]\nelements = [{}]\ntime = 5.0\n",
        numbers.join(", ")
    );
    std::fs::write(dir.join("problem.toml"), stack_problem(&death)).unwrap();
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n  contact surface a contains {side_a}\n  contact surface b contains surface_3\n\
             begin search options\n    normal tolerance = 0.8\n  end\n\
             begin interaction\n    side a a\n    side b b\n  end\n\
             begin enforcement\n    enforcement for energy = gap_conductance\n    gap conductance coefficient = gas_gap k = {K_GAS} min_gap = 1e-4\n  end\nend\n"
        ),
    )
    .unwrap();
    (dir.join("problem.toml"), upper)
}

#[test]
fn element_death_exposes_faces_of_a_skinned_block_and_removes_those_of_a_side_set() {
    let tmp = scratch("moving-death");
    let dir = tmp.path();
    let (problem, _) = dying(dir, "block_1");
    let r = run(&problem);
    let before = series_heat(G0);
    // After: half of block 1 left, the gap 0.5 wider.
    let after = 1.0 / (0.5 + (G0 + 0.5) / K_GAS + 1.0);
    let mut worst = 0.0f64;
    for s in &r.history {
        let exact = if s.time >= 5.0 { after } else { before };
        let (a, b) = s.heat[0];
        let err = ((a - exact).abs()).max((-b - exact).abs()) / exact;
        println!(
            "t = {}: heat {a} / {}, exact {exact}, rel err {err:.1e}",
            s.time, -b
        );
        worst = worst.max(err);
    }
    let m = r
        .summary
        .motion
        .expect("a run with death reports its surface updates");
    println!("{m:?}");
    assert!(worst <= 1e-9, "{worst:e}");
    assert_eq!(m.surface_updates, 1);
    // The nodes the death left alone keep the temperature they had when it came: those
    // at z = 1 on block 1, at t = 4's value.
    let mesh = &r.mesh;
    let top: Vec<usize> = mesh.blocks[0]
        .connectivity
        .iter()
        .map(|n| n.index())
        .filter(|&n| (mesh.coords[n][2] - 1.0).abs() < 1e-12)
        .collect();
    let t4 = 1.0 - 1.0 / (1.0 + G0 / K_GAS + 1.0) * 1.0;
    for &n in &top {
        let t = r.solution.temperature[n];
        assert!((t - t4).abs() <= 1e-9, "node {n}: {t} against {t4}");
    }
    // The side set of block 1's top loses its faces: nothing crosses after t = 5.
    let (problem, _) = dying(dir, "surface_2");
    let r = run(&problem);
    for s in &r.history {
        let (a, _) = s.heat[0];
        if s.time >= 5.0 {
            assert_eq!(a, 0.0, "t = {}", s.time);
        } else {
            assert!((a - before).abs() <= 1e-9 * before);
        }
    }
}

#[test]
fn death_input_that_cannot_act_is_refused_at_its_line() {
    let tmp = scratch("moving-death-refused");
    let dir = tmp.path();
    let (problem, _) = dying(dir, "block_1");
    let text = std::fs::read_to_string(&problem).unwrap();
    let check = |edit: &str| -> Vec<(String, u32)> {
        std::fs::write(&problem, edit).unwrap();
        match seam::run::check(&problem) {
            Ok(_) => Vec::new(),
            Err(RunError::Input(d, _)) => {
                d.0.iter()
                    .filter(|d| d.severity == seam::diag::Severity::Error)
                    .map(|d| (d.code.to_string(), d.loc.as_ref().map_or(0, |l| l.line)))
                    .collect()
            }
            Err(e) => panic!("{e:?}"),
        }
    };
    assert!(check(&text).is_empty());
    let line =
        |t: &str, what: &str| t.lines().position(|l| l.starts_with(what)).unwrap() as u32 + 1;
    let unknown = text.replace("elements = [", "blocks = [\"block_9\"]\nelements = [");
    assert_eq!(
        check(&unknown),
        [("E0732".into(), line(&unknown, "blocks = [\"block_9"))]
    );
    let number = text.replace("elements = [", "elements = [99999, ");
    assert_eq!(
        check(&number),
        [("E0732".into(), line(&number, "elements = [99999"))]
    );
    let steady = text.replace("kind = \"transient\"", "kind = \"steady\"");
    assert_eq!(check(&steady)[0].0, "E0732");
}

/// The two blocks carrying a species and a voltage beside the temperature, block 2
/// coming down as in [`LUA_DOWN`]: the species crosses a mass-transfer interface whose
/// coefficient is the gap law `0.05 / gap` (m/s), the voltage a Nitsche tie. c = 1 and V
/// = 1 at z = 0, c = 0 and V = 0 on block 2's top, D = σ = 1, capacities small enough
/// that every step is steady. Each step's mass flux must follow the series law at that
/// step's gap, 1 / (1 + g/0.05 + 1) — the heat law of [`series_heat`] — and the current
/// through the tie stays 1/(1 + 1) A whatever the gap.
#[test]
fn species_interfaces_and_voltage_ties_move_with_the_surfaces() {
    let tmp = scratch("moving-fields");
    let dir = tmp.path();
    ExodusWriter::create(&dir.join("mesh.exo"), &parts(G0), &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    let problem = stack_problem(&format!(
        "{LUA_DOWN}\
         [[bc]]\nkind = \"species\"\nsurfaces = [\"surface_1\"]\nvalue = 1.0\n\
         [[bc]]\nkind = \"species\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n\
         [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_1\"]\nvalue = 1.0\n\
         [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n"
    ))
    .replace(
        "conductivity = 1.0\nrho_c = 1e-12\n",
        "conductivity = 1.0\nrho_c = 1e-12\ndiffusivity = 1.0\nspecies_capacity = 1e-12\nelectrical_conductivity = 1.0\n",
    );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    let deck = |every: &str| {
        format!(
            "begin contact definition\n  contact surface a contains surface_2\n  contact surface b contains surface_3\n{every}\
             begin search options\n    normal tolerance = 0.3\n  end\n\
             begin interaction\n    side a a\n    side b b\n  end\n\
             begin enforcement thermal\n    enforcement for energy = gap_conductance\n    gap conductance coefficient = gas_gap k = {K_GAS} min_gap = 1e-4\n  end\n\
             begin enforcement mass\n    enforcement for species = gap_conductance\n    gap conductance coefficient = lua \"{K_GAS} / gap\"\n  end\n\
             begin enforcement electrical\n    enforcement for voltage = tied_voltage\n  end\nend\n"
        )
    };
    for every in ["", "  update search every 3 steps\n"] {
        std::fs::write(dir.join("contact.i"), deck(every)).unwrap();
        let r = run(&dir.join("problem.toml"));
        assert_eq!(r.history.len(), 10, "ten steps");
        let mut worst = (0.0f64, 0.0f64);
        for (s, flux) in r.history.iter().zip(&r.species_flux) {
            let exact = series_heat(G0 - SPEED * s.time);
            let (a, b) = flux[0];
            worst.0 = worst
                .0
                .max((a - exact).abs().max((-b - exact).abs()) / exact);
            let current = s.electric[0].current;
            worst.1 = worst.1.max((current - 0.5).abs() / 0.5);
        }
        eprintln!(
            "moving species and voltage tie (schedule {every:?}): worst mass flux {:.1e}, worst current {:.1e}",
            worst.0, worst.1
        );
        assert!(
            worst.0 <= 1e-8,
            "mass flux against the gap law: {:e}",
            worst.0
        );
        assert!(worst.1 <= 1e-10, "current through the tie: {:e}", worst.1);
        let m = r.summary.motion.expect("a moving run reports its searches");
        let searches = if every.is_empty() { 11 } else { 4 };
        assert_eq!(m.searches, searches, "{m:?}");
    }
    // What does not move yet: a multiplier tie of the species (its rows are made once),
    // and species interfaces or voltage ties under element death (their surfaces are
    // not made again).
    let check = |problem: &str, deck: &str| -> Vec<String> {
        std::fs::write(dir.join("checked.toml"), problem).unwrap();
        std::fs::write(dir.join("contact.i"), deck).unwrap();
        match seam::run::check(&dir.join("checked.toml")) {
            Ok(_) => Vec::new(),
            Err(RunError::Input(d, _)) => d.errors().map(|d| d.code.to_string()).collect(),
            Err(e) => panic!("{e:?}"),
        }
    };
    let problem = std::fs::read_to_string(dir.join("problem.toml")).unwrap();
    let mortar = deck("").replace(
        "enforcement for species = gap_conductance\n    gap conductance coefficient = lua \"0.05 / gap\"",
        "enforcement for species = tied multipliers = dual\n    side b variable species to species",
    );
    assert!(mortar.contains("multipliers"), "the deck was edited");
    assert_eq!(check(&problem, &mortar), ["E0731"]);
    let dying = problem.replace(LUA_DOWN, "[[death]]\nblocks = [\"block_2\"]\ntime = 5.0\n");
    assert_eq!(check(&dying, &mortar), ["E0731"]);
}

/// Element death under a species interface and a voltage tie: block 1 skinned for
/// contact, its upper layer dying at t = 5 ([`dying`]). The faces the death exposes at
/// z = 0.5 carry the species across the wider gap (mass transfer `0.05 / gap`) and the
/// current through the Nitsche tie, so each step's mass flux follows the series law of
/// that step's geometry, 1/(1 + g/0.05 + 1) before and 1/(0.5 + (g + 0.5)/0.05 + 1)
/// after, and the current 1/(1 + 1) before and 1/(0.5 + 1) after (D = σ = 1).
#[test]
fn species_interfaces_and_voltage_ties_follow_element_death() {
    let tmp = scratch("moving-fields-death");
    let dir = tmp.path();
    let (problem, _) = dying(dir, "block_1");
    let text = std::fs::read_to_string(&problem).unwrap().replace(
        "conductivity = 1.0\nrho_c = 1e-12\n",
        "conductivity = 1.0\nrho_c = 1e-12\ndiffusivity = 1.0\nspecies_capacity = 1e-12\nelectrical_conductivity = 1.0\n",
    );
    let fields = "[[bc]]\nkind = \"species\"\nsurfaces = [\"surface_1\"]\nvalue = 1.0\n\
                  [[bc]]\nkind = \"species\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n\
                  [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_1\"]\nvalue = 1.0\n\
                  [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n";
    let text = text.replace("[contact]", &format!("{fields}[contact]"));
    assert!(text.contains("diffusivity"), "the problem was edited");
    std::fs::write(&problem, text).unwrap();
    let deck = std::fs::read_to_string(dir.join("contact.i")).unwrap().replace(
        "  end\nend\n",
        "  end\n\
         begin enforcement mass\n    enforcement for species = gap_conductance\n    gap conductance coefficient = lua \"0.05 / gap\"\n  end\n\
         begin enforcement electrical\n    enforcement for voltage = tied_voltage\n  end\nend\n",
    );
    assert!(deck.contains("tied_voltage"), "the deck was edited");
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    let r = run(&problem);
    assert_eq!(r.history.len(), 10, "ten steps");
    let (mut flux_err, mut current_err) = (0.0f64, 0.0f64);
    for (s, flux) in r.history.iter().zip(&r.species_flux) {
        let after = s.time >= 5.0;
        let exact = if after {
            1.0 / (0.5 + (G0 + 0.5) / K_GAS + 1.0)
        } else {
            series_heat(G0)
        };
        let (a, b) = flux[0];
        let e = (a - exact).abs().max((-b - exact).abs()) / exact;
        let current = if after { 1.0 / 1.5 } else { 0.5 };
        let c = (s.electric[0].current - current).abs() / current;
        println!(
            "t = {}: mass flux {a} / {}, law {exact} ({e:.1e}); current {} ({c:.1e})",
            s.time, -b, s.electric[0].current
        );
        flux_err = flux_err.max(e);
        current_err = current_err.max(c);
    }
    assert!(flux_err <= 1e-8, "mass flux against the law: {flux_err:e}");
    assert!(
        current_err <= 1e-10,
        "current through the tie: {current_err:e}"
    );
    let m = r.summary.motion.expect("a run with death reports it");
    assert_eq!(m.surface_updates, 1, "{m:?}");
}

/// Electrical contacts (a contact conductance with its Joule heat) on moving and dying
/// surfaces. σ = 1, V = 1 at z = 0 and 0 on block 2's top, the contact conductance the
/// gap law `0.05 / gap` (S/m²): the current through the contact at every step is the
/// series law of that step's gap, 1/(1 + g/0.05 + 1) A. Block 2 coming down (searched
/// every step, then every 3 steps), and block 1's upper layer dying at t = 5 under the
/// lid at rest (1/(0.5 + (g + 0.5)/0.05 + 1) after).
#[test]
fn electrical_contacts_move_and_follow_element_death() {
    let tmp = scratch("moving-electric");
    let dir = tmp.path();
    let voltage = "[[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_1\"]\nvalue = 1.0\n\
                   [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n";
    let edit = |file: &Path, change: &dyn Fn(String) -> String| {
        let text = std::fs::read_to_string(file).unwrap();
        std::fs::write(file, change(text)).unwrap();
    };
    let sigma = |text: String| {
        text.replace(
            "conductivity = 1.0\nrho_c = 1e-12\n",
            "conductivity = 1.0\nrho_c = 1e-12\nelectrical_conductivity = 1.0\n",
        )
    };
    let electrical = "  end\n\
         begin enforcement electrical\n    enforcement for voltage = gap_conductance\n    gap conductance coefficient = lua \"0.05 / gap\"\n  end\nend\n";
    let worst = |r: &RunResult, law: &dyn Fn(f64) -> f64| {
        assert_eq!(r.history.len(), 10, "ten steps");
        let mut worst = 0.0f64;
        for s in &r.history {
            let (current, exact) = (s.electric[0].current, law(s.time));
            println!("t = {}: current {current}, law {exact}", s.time);
            worst = worst.max((current - exact).abs() / exact);
        }
        worst
    };
    // Closing: every step, then every 3 steps.
    for (every, searches) in [(None, 11), (Some(3), 4)] {
        let problem = closing(dir, &format!("{LUA_DOWN}{voltage}"), every);
        edit(&problem, &sigma);
        edit(&dir.join("contact.i"), &|d| {
            d.replace("  end\nend\n", electrical)
        });
        let r = run(&problem);
        let e = worst(&r, &|t| series_heat(G0 - SPEED * t));
        println!("closing, schedule {every:?}: worst current {e:.1e}");
        assert!(e <= 1e-9, "current against the gap law: {e:e}");
        let m = r.summary.motion.expect("a moving run reports its searches");
        assert_eq!(m.searches, searches, "{m:?}");
    }
    // Element death.
    let (problem, _) = dying(dir, "block_1");
    edit(&problem, &|p| {
        sigma(p).replace("[contact]", &format!("{voltage}[contact]"))
    });
    edit(&dir.join("contact.i"), &|d| {
        d.replace("  end\nend\n", electrical)
    });
    let r = run(&problem);
    let e = worst(&r, &|t| match t >= 5.0 {
        true => 1.0 / (0.5 + (G0 + 0.5) / K_GAS + 1.0),
        false => series_heat(G0),
    });
    println!("death: worst current {e:.1e}");
    assert!(e <= 1e-9, "current against the series law: {e:e}");
}

/// A periodic electrical contact does not move (its map stays with the Energy entry):
/// the turbine sector's cut faces joined by a voltage contact conductance under a
/// `[displacement]` is refused with E0731, and the same without the displacement
/// passes the check.
#[test]
fn a_periodic_electrical_contact_that_would_move_is_refused() {
    let scene = crate::examples::copy_scene_as("turbine_sector", "moving-periodic-electric");
    let dir = scene.path();
    let problem = std::fs::read_to_string(dir.join("problem.toml"))
        .unwrap()
        .replace(
            "conductivity = 20.0\n",
            "conductivity = 20.0\nrho_c = 1e6\nelectrical_conductivity = 1e6\n",
        )
        .replace(
            "[solve]\nkind = \"steady\"\n",
            "[[bc]]\nkind = \"voltage\"\nsurfaces = [\"bore\"]\nvalue = 0.0\n\
             [initial]\ntemperature = 300.0\n\
             [solve]\nkind = \"transient\"\ndt = 1.0\nend_time = 2.0\n",
        );
    assert!(problem.contains("transient"), "the problem was edited");
    let deck = std::fs::read_to_string(dir.join("contact.i"))
        .unwrap()
        .replace(
            "    enforcement for energy = tied\n    side b variable temperature to temperature\n  end\n",
            "    enforcement for energy = tied_temperature\n  end\n\
             begin enforcement electrical\n    enforcement for voltage = gap_conductance\n    gap conductance coefficient = constant h = 1e8\n  end\n",
        );
    assert!(deck.contains("for voltage"), "the deck was edited");
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    let check = |text: &str| -> Vec<String> {
        std::fs::write(dir.join("checked.toml"), text).unwrap();
        match seam::run::check(&dir.join("checked.toml")) {
            Ok(_) => Vec::new(),
            Err(RunError::Input(d, _)) => d
                .errors()
                .map(|d| format!("{}: {}", d.code, d.message))
                .collect(),
            Err(e) => panic!("{e:?}"),
        }
    };
    assert_eq!(check(&problem), Vec::<String>::new());
    let moving = problem.replace(
        "[contact]",
        "[displacement]\nvalue = [0.0, 0.0, 0.0]\n[contact]",
    );
    let refused = check(&moving);
    assert_eq!(refused.len(), 1, "{refused:?}");
    let why = "electrical contact start / end is a periodic pair";
    assert!(
        refused[0].starts_with("E0731") && refused[0].contains(why),
        "{refused:?}"
    );
}
