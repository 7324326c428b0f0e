//! `trocar simulate ROBOT --trajectory PATH.csv`: a user's robot along a user's tip path, and the
//! trajectories refused (each error names the file, the row and the column, and writes nothing).

mod common;
use common::{fresh_dir, panda_tip, trocar, ur5_with_section, PANDA_Q0};

const Q0: &str = PANDA_Q0;

fn dir(name: &str) -> std::path::PathBuf {
    fresh_dir("user-trajectory", name)
}

/// The Panda's tip at q0, from `trocar eval`.
fn start_tip() -> [f64; 3] {
    panda_tip()
}

/// A 10 s circle of radius 1 cm through the start tip, in the plane normal to the shaft (the
/// base's x-y plane at q0), with the roll held at 0.
fn circle_csv() -> String {
    let c = start_tip();
    let mut s = String::from("t,x,y,z,roll\n");
    for k in 0..=200 {
        let t = k as f64 * 0.05;
        let a = 2.0 * std::f64::consts::PI * t / 10.0;
        s += &format!(
            "{t},{},{},{},0\n",
            c[0] + 0.01 * (a.cos() - 1.0),
            c[1] + 0.01 * a.sin(),
            c[2]
        );
    }
    s
}

fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn panda_follows_a_circle_through_the_trocar() {
    let d = dir("circle");
    let path = d.join("circle.csv");
    std::fs::write(&path, circle_csv()).unwrap();
    let out = d.join("out.csv");
    let (code, _, err) = trocar(&[
        "simulate",
        "panda-laparoscope",
        "--trajectory",
        path.to_str().unwrap(),
        "--q0",
        Q0,
        "--csv",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("max drift"), "{err}");
    let csv = std::fs::read_to_string(&out).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with("t,ep_norm,eo_norm,vr_x,vr_y,rcm_drift,w_r,w_i,l_a,q1,"),
        "{header}"
    );
    let t = column(&csv, "t");
    assert!((t[t.len() - 1] - 10.0).abs() < 1e-9);
    let drift = column(&csv, "rcm_drift");
    assert!(
        drift.iter().all(|d| *d <= 1e-4),
        "drift {}",
        drift.iter().cloned().fold(0.0, f64::max)
    );
    let ep = column(&csv, "ep_norm");
    let after = t
        .iter()
        .zip(&ep)
        .filter(|(t, _)| **t >= 2.0)
        .map(|(_, e)| *e)
        .fold(0.0, f64::max);
    assert!(after <= 1e-3, "tip error after 2 s {after}");
    // No joint beyond its URDF limits (from the description, via `trocar preset`'s URDF).
    let limits = [
        [-2.8973, 2.8973],
        [-1.7628, 1.7628],
        [-2.8973, 2.8973],
        [-3.0718, -0.0698],
        [-2.8973, 2.8973],
        [-0.0175, 3.7525],
        [-2.8973, 2.8973],
    ];
    for (k, [lo, hi]) in limits.iter().enumerate() {
        let q = column(&csv, &format!("q{}", k + 1));
        assert!(
            q.iter().all(|v| v >= lo && v <= hi),
            "joint {} left its limits",
            k + 1
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_trajectories_name_the_file_row_and_column_and_write_nothing() {
    let d = dir("bad");
    let good = circle_csv();
    let rows: Vec<&str> = good.lines().collect();
    let swapped = {
        let mut r = rows.clone();
        r.swap(3, 4);
        r.join("\n")
    };
    let nan = good.replacen(
        &rows[5][..rows[5].find(',').unwrap() + 1],
        &format!("{}NaN_", &rows[5][..rows[5].find(',').unwrap() + 1]),
        1,
    );
    let cases: Vec<(&str, String, &str)> = vec![
        ("unsorted", swapped, ":5: column `t`"),
        ("nan", nan, ":6: column `x`"),
        (
            "missing",
            good.replace("t,x,y,z,roll", "t,x,q,z,roll"),
            ":1: no column `y`",
        ),
        (
            "one-row",
            format!("{}\n{}\n", rows[0], rows[1]),
            ":2: column `t`: 1 row; a trajectory needs at least two",
        ),
        (
            "no-row",
            format!("{}\n", rows[0]),
            ":1: column `t`: 0 rows; a trajectory needs at least two",
        ),
        (
            "no-roll",
            rows.iter()
                .map(|r| r.rsplit_once(',').unwrap().0)
                .collect::<Vec<_>>()
                .join("\n"),
            ":1: the task of `panda_laparoscope` commands a rotation and the header has no column `roll`",
        ),
        (
            "far",
            format!("{}\n{}\n1000,5,5,5,0\n", rows[0], rows[1]),
            ":3: columns x, y, z: the point is",
        ),
        (
            // Comment lines count: the rows are named by their line in the file.
            "far-after-comments",
            format!("# a path\n\n{}\n{}\n1000,5,5,5,0\n", rows[0], rows[1]),
            ":5: columns x, y, z: the point is",
        ),
        (
            // A jump between rows close in time: the feed-forward would be 5e7 m/s.
            "fast",
            {
                let c = start_tip();
                format!(
                    "{}\n0,{},{},{},0\n1,{},{},{},0\n1.000000001,{},{},{},0\n",
                    rows[0],
                    c[0],
                    c[1],
                    c[2],
                    c[0],
                    c[1],
                    c[2],
                    c[0] + 0.05,
                    c[1],
                    c[2]
                )
            },
            ":4: columns x, y, z: the tip would move at 5.0000e7 m/s",
        ),
        (
            // The tip 0.1 m on the robot's side of the trocar (the shaft points down at q0,
            // the trocar 0.15 m above the tip): the instrument would be pulled out.
            "behind",
            {
                let c = start_tip();
                format!(
                    "{}\n{}\n10,{},{},{},0\n",
                    rows[0],
                    rows[1],
                    c[0],
                    c[1],
                    c[2] + 0.25
                )
            },
            ":3: columns x, y, z: the point is behind the trocar",
        ),
        (
            "nan-literal",
            good.replacen(&format!(",{},", start_tip()[2]), ",NaN,", 1),
            ":2: column `z`: NaN is not finite",
        ),
        (
            "huge",
            good.replacen(&format!(",{},", start_tip()[2]), ",2e6,", 1),
            ":2: column `z`: 2e6 is beyond",
        ),
        (
            "off-start",
            good.replacen(&format!(",{},", start_tip()[2]), &format!(",{},", start_tip()[2] + 0.01), 1),
            ":2: columns x, y, z: the first point is 0.0100 m from the tip at q0",
        ),
        (
            "short-row",
            good.replacen(&format!("{}\n", rows[7]), &format!("{}\n", rows[7].rsplit_once(',').unwrap().0), 1),
            ":8: 4 values, the header names 5 columns (no value for column `roll`)",
        ),
    ];
    for (name, text, want) in cases {
        let path = d.join(format!("{name}.csv"));
        std::fs::write(&path, &text).unwrap();
        let out = d.join(format!("{name}-out.csv"));
        let (code, _, err) = trocar(&[
            "simulate",
            "panda-laparoscope",
            "--trajectory",
            path.to_str().unwrap(),
            "--q0",
            Q0,
            "--csv",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(err.contains(want), "{name}: {err}");
        if want.starts_with(':') {
            assert!(
                err.contains(&format!("{name}.csv{want}")),
                "{name}: the file and row: {err}"
            );
        }
        assert!(!out.exists(), "{name}: an output was written");
    }
    // Without --q0: the error says how to give it.
    let path = d.join("circle.csv");
    std::fs::write(&path, &good).unwrap();
    let (code, _, err) = trocar(&[
        "simulate",
        "panda-laparoscope",
        "--trajectory",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(
        err.starts_with("error: --q0: ") && err.contains("q1,...,q7"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The UR5 example's start configuration `(0, −π/2, π/2, −π/2, −π/2, 0)`: the instrument
/// points down.
const UR5_Q0: &str =
    "0,-1.5707963267948966,1.5707963267948966,-1.5707963267948966,-1.5707963267948966,0";

/// The `<limit lower upper>` of every movable joint of a URDF, read from its text.
fn urdf_limits(path: &str) -> Vec<[f64; 2]> {
    let text = std::fs::read_to_string(path).unwrap();
    let attribute = |tag: &str, name: &str| -> f64 {
        let at = tag.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        tag[at..at + tag[at..].find('"').unwrap()].parse().unwrap()
    };
    text.split("<joint ")
        .skip(1)
        .filter(|j| !j.contains("type=\"fixed\""))
        .map(|j| {
            let limit = &j[j.find("<limit").unwrap()..];
            let limit = &limit[..limit.find("/>").unwrap()];
            [attribute(limit, "lower"), attribute(limit, "upper")]
        })
        .collect()
}

/// A user's UR5 description (chain from its URDF, a 0.35 m shaft through a trocar on the last
/// link) along the shipped 10 s circle: the run holds the trocar, follows the path, keeps every
/// joint inside its URDF range, and draws the same figure, still and animation as a scenario.
#[test]
fn ur5_follows_the_example_circle_and_is_drawn() {
    let d = dir("ur5");
    let [csv, plot, gif, still] = ["run.csv", "run.png", "run.gif", "still.svg"].map(|f| d.join(f));
    let (code, _, err) = trocar(&[
        "simulate",
        "examples/robots/ur5_trocar.toml",
        "--trajectory",
        "examples/trajectories/ur5-circle.csv",
        "--q0",
        UR5_Q0,
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
        "--animate",
        gif.to_str().unwrap(),
        "--snapshot",
        still.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    for word in [
        "max tip error",
        "after the first second",
        "max orientation error",
        "peak joint rate",
        "max drift",
        "max lateral velocity",
        "closest approach to a joint limit",
    ] {
        assert!(err.contains(word), "summary: {err}");
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    let header = text.lines().next().unwrap();
    assert!(
        header.starts_with("t,ep_norm,eo_norm,vr_x,vr_y,rcm_drift,w_r,w_i,l_a,q1,")
            && header.ends_with(",qd6"),
        "{header}"
    );
    let t = column(&text, "t");
    assert!((t[t.len() - 1] - 10.0).abs() < 1e-9, "the run lasts 10 s");
    let drift = column(&text, "rcm_drift").into_iter().fold(0.0, f64::max);
    assert!(drift <= 1e-4, "drift {drift} m");
    let ep = column(&text, "ep_norm");
    let after = t
        .iter()
        .zip(&ep)
        .filter(|(t, _)| **t >= 2.0)
        .map(|(_, e)| *e)
        .fold(0.0, f64::max);
    assert!(after <= 1e-3, "tip error after 2 s {after} m");
    let limits = urdf_limits(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/robots/urdf/ur5.urdf"
    ));
    assert_eq!(limits.len(), 6);
    let mut margin = f64::INFINITY;
    for (k, [lo, hi]) in limits.iter().enumerate() {
        for v in column(&text, &format!("q{}", k + 1)) {
            margin = margin.min((v - lo).min(hi - v));
        }
    }
    assert!(
        margin >= 0.0,
        "a joint left its URDF range by {} rad",
        -margin
    );
    eprintln!("ur5: drift {drift:.3e} m, tip error after 2 s {after:.3e} m, joint-limit margin {margin:.4} rad");
    // The figure and the still are images; the animation has the default 50 frames.
    assert_eq!(&std::fs::read(&plot).unwrap()[1..4], b"PNG");
    assert!(std::fs::read_to_string(&still)
        .unwrap()
        .contains("ur5_trocar along ur5-circle.csv"));
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options
        .read_info(std::fs::File::open(&gif).unwrap())
        .unwrap();
    let mut frames = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 50);
    let _ = std::fs::remove_dir_all(&d);
}

/// `trocar simulate my_arm.toml` runs the description's own `[simulation]`; the flags override
/// it; a bad entry is refused with the file, the line and the field, and nothing is written.
#[test]
fn a_description_carries_its_own_scenario() {
    let d = dir("section");
    let q0 = format!("q0 = [{}]\n", UR5_Q0.replace(',', ", "));
    let arm = ur5_with_section(
        &d,
        &format!("trajectory = \"circle.csv\"\n{q0}method = \"dls\"\n"),
    );
    let out = d.join("own.csv");
    let (code, _, err) = trocar(&[
        "simulate",
        arm.to_str().unwrap(),
        "--csv",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("circle.csv (Dls,"), "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    let t = column(&text, "t");
    assert!((t[t.len() - 1] - 10.0).abs() < 1e-9);
    assert!(column(&text, "rcm_drift").iter().all(|v| *v <= 1e-4));

    // A flag overrides the section: --method qp, and --q0 of the wrong length is refused as a
    // flag (the section's q0 is not used).
    let (code, _, err) = trocar(&[
        "simulate",
        arm.to_str().unwrap(),
        "--method",
        "qp",
        "--csv",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("(Qp,"), "{err}");
    let (code, _, err) = trocar(&["simulate", arm.to_str().unwrap(), "--q0", "0,0"]);
    assert_eq!(code, 1);
    assert!(err.contains("--q0: 2 values given"), "{err}");

    // Without a trajectory anywhere: how to give one.
    let bare = ur5_with_section(&d.join("bare"), &q0);
    let (code, _, err) = trocar(&["simulate", bare.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(
        err.starts_with("error: --trajectory: ") && err.contains("[simulation] section"),
        "{err}"
    );

    // Bad entries: the file, the line (the section's first entry, the line after its header)
    // and the field.
    let example = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/robots/ur5_trocar.toml"
    ))
    .unwrap();
    let first = example[..example.find("[simulation]").unwrap()]
        .lines()
        .count()
        + 2;
    let cases = [
        (
            "q0 = [0, 1]\n",
            first,
            "simulation.q0",
            "2 values; the robot has 6 joints",
        ),
        (
            "trajectory = \"circle.csv\"\nq0 = [0, nan, 0, 0, 0, 0]\n",
            first + 1,
            "simulation.q0[1]",
            "not finite",
        ),
        ("kp = -5\n", first, "simulation.kp", "must be ≥ 0"),
        (
            "method = \"fast\"\n",
            first,
            "simulation.method",
            "unknown method `fast`",
        ),
        (
            "trocar = [0, 0, 2e6]\n",
            first,
            "simulation.trocar[2]",
            "beyond",
        ),
        (
            "speed = 1\n",
            first,
            "simulation.speed",
            "unknown key `speed`",
        ),
    ];
    for (k, (section, line, field, words)) in cases.into_iter().enumerate() {
        let arm = ur5_with_section(&d.join(format!("bad{k}")), section);
        let out = d.join(format!("bad{k}.csv"));
        let (code, _, err) = trocar(&[
            "simulate",
            arm.to_str().unwrap(),
            "--csv",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 1, "{section}: {err}");
        assert!(
            err.contains(&format!("arm.toml:{line}:")) && err.contains(&format!("field `{field}`")),
            "{section}: {err}"
        );
        assert!(err.contains(words), "{section}: {err}");
        assert!(!out.exists(), "{section}: an output was written");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// The "Your own robot" commands of `docs/simulation.md`, as written there (outputs redirected to a
/// temporary directory): each exits with 0 and writes its files.
#[test]
fn the_readmes_own_robot_commands_run() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let readme = std::fs::read_to_string(format!("{root}/docs/simulation.md")).unwrap();
    let section = &readme[readme.find("## Your own robot,").expect("the section")..];
    let block = section
        .split("```sh\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("a sh block");
    let commands: Vec<String> = block
        .replace("\\\n", " ")
        .lines()
        .map(|l| l.split(" # ").next().unwrap().trim().to_string())
        .filter(|l| !l.is_empty())
        .collect();
    assert_eq!(commands.len(), 4, "four commands: {commands:?}");
    let d = dir("readme");
    let mut written = Vec::new();
    for command in &commands {
        let args = command
            .strip_prefix("cargo run --release --bin trocar -- ")
            .unwrap_or_else(|| panic!("not a trocar command: {command}"));
        let mut argv: Vec<String> = args.split_whitespace().map(String::from).collect();
        for k in 1..argv.len() {
            if ["-o", "--csv", "--plot", "--animate", "--snapshot"].contains(&argv[k - 1].as_str())
            {
                let out = d.join(&argv[k]);
                written.push(out.clone());
                argv[k] = out.to_str().unwrap().to_string();
            }
        }
        let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
        let (code, _, err) = trocar(&argv);
        assert_eq!(code, 0, "{command}: {err}");
    }
    assert_eq!(written.len(), 5, "{written:?}");
    for f in &written {
        assert!(std::fs::metadata(f).unwrap().len() > 0, "{}", f.display());
    }
    let _ = std::fs::remove_dir_all(&d);
}
