//! `trocar register-port`: the port located from a run's joint positions. The run is `trocar
//! simulate panda-laparoscope` (its shaft held within 1e-7 m of the trocar); the port found from
//! its CSV is checked against the trocar computed independently — the constraint frame's origin
//! at the first row's joints, from `trocar eval`'s generated closed forms (`fk0i` composed with
//! `constraint_frame`). Then what cannot locate a port: a still instrument (one pose repeated),
//! missing columns, values that are not numbers, a robot without a constraint, bad options —
//! each refused with the file, line and column or the option, and nothing on stdout.

mod common;

use common::{fresh_dir, json_matrix, trocar};

fn field(json: &str, name: &str) -> String {
    let start = json.find(&format!("\"{name}\": ")).unwrap() + name.len() + 4;
    let rest = &json[start..];
    let end = if rest.starts_with('[') {
        rest.find(']').unwrap() + 1
    } else {
        rest.find([',', '}']).unwrap()
    };
    rest[..end].to_string()
}

fn numbers(text: &str) -> Vec<f64> {
    text.trim_matches(['[', ']'])
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect()
}

#[test]
fn the_port_of_a_run_is_its_trocar() {
    let dir = fresh_dir("register_port", "run");
    let csv = dir.join("run.csv");
    let (code, _, stderr) = trocar(&[
        "simulate",
        "panda-laparoscope",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let first: Vec<f64> = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let rows = text.lines().count() - 1;
    let q: Vec<String> = (1..=7)
        .map(|k| first[header.iter().position(|c| *c == format!("q{k}")).unwrap()].to_string())
        .collect();
    let l_a = first[header.iter().position(|c| *c == "l_a").unwrap()];

    // The trocar: g_0i(q0) g_ir(l_a) at the run's start, from the generated closed forms.
    let q_arg = q.join(",");
    let (code, fk0i, stderr) = trocar(&[
        "eval",
        "panda-laparoscope",
        "--q",
        &q_arg,
        "--what",
        "fk0i",
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (code, frame, stderr) = trocar(&[
        "eval",
        "panda-laparoscope",
        "--q",
        &q_arg,
        "--param",
        &format!("l_a={l_a}"),
        "--what",
        "constraint_frame",
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (_, _, g) = json_matrix(&fk0i);
    let (_, _, f) = json_matrix(&frame);
    let expected: Vec<f64> = (0..3)
        .map(|r| g[r][3] + (0..3).map(|c| g[r][c] * f[c][3]).sum::<f64>())
        .collect();

    let (code, json, stderr) = trocar(&[
        "register-port",
        "panda-laparoscope",
        "--joints",
        csv.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let port = numbers(&field(&json, "port"));
    let distance = (0..3)
        .map(|k| (port[k] - expected[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        distance <= 1e-6,
        "port {port:?}, trocar {expected:?}: {distance:e} m apart"
    );
    assert_eq!(field(&json, "lines").parse::<usize>().unwrap(), rows);
    let residual: f64 = field(&json, "residual").parse().unwrap();
    assert!(residual <= 1e-6, "residual {residual:e}");
    let spread: f64 = field(&json, "spread_deg").parse().unwrap();
    assert!(spread > 2.0, "spread {spread}°");

    // The text form says the same point.
    let (code, out, _) = trocar(&[
        "register-port",
        "panda-laparoscope",
        "--joints",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    assert!(
        out.starts_with(&format!(
            "port (m, base frame): {:.6} {:.6} {:.6}",
            port[0], port[1], port[2]
        )),
        "{out}"
    );
    assert!(out.contains("spread:") && out.contains("poses"), "{out}");

    // A pivot too small for the least spread asked.
    let (code, out, stderr) = trocar(&[
        "register-port",
        "panda-laparoscope",
        "--joints",
        csv.to_str().unwrap(),
        "--least-spread",
        "30",
    ]);
    assert_ne!(code, 0);
    assert!(out.is_empty());
    assert!(
        stderr.contains("nearly parallel") && stderr.contains("30.000°"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn what_cannot_locate_a_port_is_refused_where_it_is_wrong() {
    let dir = fresh_dir("register_port", "refused");
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let q0 = "0,-0.3,0,-2.2,0,2.0,0.8";
    let still = write(
        "still.csv",
        &format!("q1,q2,q3,q4,q5,q6,q7\n{q0}\n{q0}\n{q0}\n"),
    );
    let missing = write("missing.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n");
    let bad = write(
        "bad.csv",
        &format!("# a comment\nq1,q2,q3,q4,q5,q6,q7\n{q0}\n0,x,0,-2.2,0,2.0,0.8\n"),
    );
    let empty = write("empty.csv", "q1,q2,q3,q4,q5,q6,q7\n");
    let cases: Vec<(Vec<String>, String)> = vec![
        (
            vec!["panda-laparoscope".into(), "--joints".into(), still.clone()],
            "nearly parallel".into(),
        ),
        (
            vec![
                "panda-laparoscope".into(),
                "--joints".into(),
                missing.clone(),
            ],
            format!("{missing}:1: no column `q7`"),
        ),
        (
            vec!["panda-laparoscope".into(), "--joints".into(), bad.clone()],
            format!("{bad}:4: column q2 (field 2): `x` is not a finite number"),
        ),
        (
            vec!["panda-laparoscope".into(), "--joints".into(), empty.clone()],
            "no rows of joint positions".into(),
        ),
        (
            vec![
                "panda-laparoscope".into(),
                "--joints".into(),
                dir.join("absent.csv").to_str().unwrap().into(),
            ],
            "cannot read the joint positions".into(),
        ),
        (
            vec![
                "panda-laparoscope".into(),
                "--joints".into(),
                still.clone(),
                "--forgetting".into(),
                "1.5".into(),
            ],
            "forgetting factor 1.5".into(),
        ),
        (
            vec![
                "panda-laparoscope".into(),
                "--joints".into(),
                still.clone(),
                "--least-spread".into(),
                "-1".into(),
            ],
            "the least spread".into(),
        ),
        (
            vec!["four-bar".into(), "--joints".into(), still.clone()],
            "closed mechanism".into(),
        ),
    ];
    for (args, expected) in cases {
        let mut all = vec!["register-port"];
        all.extend(args.iter().map(String::as_str));
        let (code, out, stderr) = trocar(&all);
        assert_ne!(code, 0, "{args:?}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert!(stderr.contains(&expected), "{args:?}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
