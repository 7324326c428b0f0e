//! Every description file shipped in `runtime/model/robots/` is listed by `trocar list`, passes
//! `trocar verify` by its name, and runs briefly along a path held at its tip with every method
//! (`--method all`), as a user's robot does (docs/RELIABILITY.md F24). `iiwa-endoscope` and
//! `iiwa-link6` were shipped as files but not as names: not listed, and `trocar verify
//! iiwa-endoscope` could not read the file.

mod common;
use common::{json_matrix, trocar};

/// The file stems of `runtime/model/robots/*.toml`, sorted.
fn shipped_files() -> Vec<String> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../runtime/model/robots");
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert!(names.len() >= 8, "{names:?}");
    names
}

/// A start configuration inside every shipped robot's joint ranges, away from singularities.
fn q0(joints: usize) -> &'static str {
    match joints {
        7 => "0.1,0.4,0.1,-1.2,0.1,0.8,0.2",
        8 => "0.0,-0.3,0.9,0.2,-0.6,0.1,0.5,0.3",
        n => panic!("no start configuration for {n} joints"),
    }
}

#[test]
fn every_shipped_description_is_listed_verified_and_simulated() {
    let (code, list, err) = trocar(&["list"]);
    assert_eq!(code, 0, "{err}");
    let robots: Vec<&str> = list
        .lines()
        .skip_while(|l| !l.starts_with("robots"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .map(str::trim)
        .collect();
    let dir = std::env::temp_dir().join(format!("trocar-shipped-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in shipped_files() {
        assert!(
            robots.contains(&name.as_str()),
            "{name} not in `trocar list`:\n{list}"
        );
        let (code, out, err) = trocar(&["verify", &name, "--samples", "50"]);
        assert_eq!(code, 0, "trocar verify {name}:\n{out}{err}");
        assert!(out.contains("all checks passed"), "{name}:\n{out}");

        // Every shipped robot is serial with a [constraint] of sizes the run-time controller
        // has: 0.2 s held at the tip, with each method.
        let (code, out, err) = trocar(&["preset", &name]);
        assert_eq!(code, 0, "{err}");
        assert!(out.contains("[constraint]"), "{name}");
        let joints = {
            let (_, _, err) = trocar(&["eval", &name, "--q", "0", "--what", "fk"]);
            // "--q: 1 values given, `NAME` has N joints (...)"
            let before = err.split(" joints").next().unwrap();
            before
                .rsplit(' ')
                .next()
                .unwrap()
                .parse::<usize>()
                .expect(&err)
        };
        let q = q0(joints);
        let (code, out, err) = trocar(&["eval", &name, "--q", q, "--what", "fk", "--json"]);
        assert_eq!(code, 0, "{err}");
        let (_, _, m) = json_matrix(&out);
        let tip = format!("{},{},{}", m[0][3], m[1][3], m[2][3]);
        let path = dir.join(format!("{name}.csv"));
        std::fs::write(&path, format!("t,x,y,z,roll\n0,{tip},0\n0.2,{tip},0\n")).unwrap();
        let plot = dir.join(format!("{name}.svg"));
        let (code, _, err) = trocar(&[
            "simulate",
            &name,
            "--trajectory",
            path.to_str().unwrap(),
            "--q0",
            q,
            "--method",
            "all",
            "--plot",
            plot.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "trocar simulate {name}:\n{err}");
        for method in ["Pinv", "Dls", "Fi", "Qp"] {
            assert!(
                err.contains(&format!("({method}, 100 steps")),
                "{name}:\n{err}"
            );
        }
        assert!(std::fs::metadata(&plot).unwrap().len() > 0);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
