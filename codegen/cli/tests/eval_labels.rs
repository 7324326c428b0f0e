//! `trocar eval` as text names its rows and columns: the twist components a Jacobian maps to,
//! and what its columns multiply; the numbers are those of the JSON output.

mod common;

/// `trocar ARGS`, which must succeed: its stdout.
fn trocar(args: &[&str]) -> String {
    let (code, out, err) = common::trocar(args);
    assert_eq!(code, 0, "{err}");
    out
}

/// `(column labels, [(row label, numbers)])` of labelled text.
fn parse(text: &str) -> (Vec<String>, Vec<(String, Vec<f64>)>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split_whitespace()
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| {
            let mut w = l.split_whitespace();
            let label = w.next().unwrap().to_owned();
            (label, w.map(|x| x.parse().unwrap()).collect())
        })
        .collect();
    (header, rows)
}

const Q8: &str = "--q=0,-0.3,0.9,0.2,-0.6,0.1,0.5,0.3";
const TWIST: [&str; 6] = ["v_x", "v_y", "v_z", "w_x", "w_y", "w_z"];

#[test]
fn constrained_jacobian_columns_are_v0i_and_the_joints_after_the_link() {
    let (cols, rows) = parse(&trocar(&["eval", "bidirectional-zy", Q8, "--what", "jr"]));
    // (3.15): J^r = [Ad_gei Λ# | J^B_0e2], 6 − r = 4 columns of v0i, then joints 7 and 8.
    assert_eq!(
        cols,
        [
            "v0i[1]",
            "v0i[2]",
            "v0i[3]",
            "v0i[4]",
            "dq_shaft_7",
            "dq_shaft_8"
        ]
    );
    assert_eq!(rows.iter().map(|r| r.0.as_str()).collect::<Vec<_>>(), TWIST);
    let (_, _, json) = common::json_matrix(&trocar(&[
        "eval",
        "bidirectional-zy",
        Q8,
        "--what",
        "jr",
        "--json",
    ]));
    for ((_, printed), exact) in rows.iter().zip(&json) {
        for (a, b) in printed.iter().zip(exact) {
            assert!((a - b).abs() <= 5e-10, "{a} vs {b}");
        }
    }
}

#[test]
fn the_task_rows_are_the_selected_components() {
    let q = "--q=0.1,-0.4,0.2,-2.0,0.1,1.8,0.7";
    let (cols, rows) = parse(&trocar(&["eval", "panda-laparoscope", q, "--what", "task"]));
    assert_eq!(cols.len(), 4);
    // [task] select = x y z rz: v_x v_y v_z w_z of the tip's body twist.
    let labels: Vec<&str> = rows.iter().map(|r| r.0.as_str()).collect();
    assert_eq!(labels, ["v_x", "v_y", "v_z", "w_z"]);
    let (cols, _) = parse(&trocar(&["eval", "panda-laparoscope", q, "--what", "jb0i"]));
    assert_eq!(cols[0], "dq_panda_joint1");
    assert_eq!(cols.len(), 7);
}

#[test]
fn constraint_jacobian_and_mechanism_labels() {
    let (cols, _) = parse(&trocar(&["eval", "bidirectional-zy", Q8, "--what", "jc"]));
    assert_eq!(cols, ["dv0r[1]", "dv0r[2]"]);
    let q = "--q=0.3,1.2,2.0,0";
    let (cols, rows) = parse(&trocar(&["eval", "four-bar", q, "--what", "passive"]));
    assert_eq!(cols, ["dq_theta1"]);
    assert_eq!(rows.len(), 3);
    assert!(rows
        .iter()
        .all(|r| r.0.starts_with("dq_theta") && r.0 != "dq_theta1"));
}

#[test]
fn scalars_and_poses_stay_plain() {
    let w = trocar(&["eval", "bidirectional-zy", Q8, "--what", "manip"]);
    assert!(w.trim().parse::<f64>().is_ok(), "{w}");
    let fk = trocar(&["eval", "bidirectional-zy", Q8, "--what", "fk"]);
    assert_eq!(fk.lines().count(), 4);
    assert!(
        fk.split_whitespace().all(|x| x.parse::<f64>().is_ok()),
        "{fk}"
    );
}

/// `--what a,b,...`: each quantity under its name, the values of asking for it alone (to
/// rounding: one program shares their common values), in the order given; errors for a name
/// given twice or an empty one.
#[test]
fn several_quantities_are_each_the_answer_alone() {
    let q = "--q=0.1,-0.4,0.2,-2.0,0.1,1.8,0.7";
    let json = trocar(&[
        "eval",
        "panda-laparoscope",
        q,
        "--what",
        "jb0i,fk0i,manip",
        "--json",
    ]);
    let both: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(both.as_object().unwrap().len(), 3);
    // In the order asked for.
    let at = |name: &str| json.find(&format!("\"{name}\":")).unwrap();
    assert!(
        at("jb0i") < at("fk0i") && at("fk0i") < at("manip"),
        "{json}"
    );
    for name in ["jb0i", "fk0i", "manip"] {
        let alone: serde_json::Value = serde_json::from_str(&trocar(&[
            "eval",
            "panda-laparoscope",
            q,
            "--what",
            name,
            "--json",
        ]))
        .unwrap();
        let numbers = |v: &serde_json::Value| -> Vec<f64> {
            v["data"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|row| row.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
                .collect()
        };
        let (a, b) = (numbers(&both[name]), numbers(&alone));
        assert_eq!(a.len(), b.len(), "{name}");
        assert_eq!(both[name]["rows"], alone["rows"], "{name}");
        let d = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-14, "{name}: {d:e}");
    }
    // Text: each matrix under a heading, jb0i with its labels.
    let text = trocar(&["eval", "panda-laparoscope", q, "--what", "fk0i,jb0i"]);
    assert!(text.starts_with("fk0i (forward_kinematics_i):\n"), "{text}");
    assert!(
        text.contains("\n\njb0i (partial_body_jacobian):\n"),
        "{text}"
    );
    assert!(text.contains("dq_panda_joint7"), "{text}");
    // --numeric and a mechanism: each quantity from its own evaluation, the numbers of asking
    // for it alone.
    for (robot, q, what) in [
        ("panda-laparoscope", q, "--numeric"),
        ("four-bar", "--q=0.5,1.2,0.3,0.9", ""),
    ] {
        let names = if robot == "four-bar" {
            ["jr", "det"]
        } else {
            ["fk", "jb0i"]
        };
        let mut args = vec!["eval", robot, q, "--what"];
        let joined = names.join(",");
        args.push(&joined);
        args.push("--json");
        if !what.is_empty() {
            args.push(what);
        }
        let both: serde_json::Value = serde_json::from_str(&trocar(&args)).unwrap();
        for name in names {
            let mut alone_args = vec!["eval", robot, q, "--what", name, "--json"];
            if !what.is_empty() {
                alone_args.push(what);
            }
            let alone: serde_json::Value = serde_json::from_str(&trocar(&alone_args)).unwrap();
            assert_eq!(both[name], alone, "{robot} {name}");
        }
    }
    for (what, message) in [
        ("fk,jb0i,fk", "`fk` asked for twice"),
        ("fk,,jb0i", "an empty name"),
        ("fk,nope", "not a quantity"),
    ] {
        let (code, _, err) = common::trocar(&["eval", "panda-laparoscope", q, "--what", what]);
        assert_eq!(code, 1, "{what}");
        assert!(err.contains(message), "{what}: {err}");
    }
}
