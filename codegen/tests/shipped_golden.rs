//! Golden output of every shipped robot, closed mechanism and generated-code fixture, in `f32` and
//! `f64`, each pair stored once (`tests/snapshots/shipped/`):
//!
//! - `<stem>_f64.rs` is the `f64` module, byte for byte;
//! - the `f32` module is **the `f64` golden with every `f64` replaced by `f32`** (the three bytes,
//!   wherever they occur: types, `0.25_f64`, `<f64 as ::trocar::emitted::Real>`), **then patched by
//!   `<stem>_f32.diff`** when that file exists. The diff holds only the lines the replacement does
//!   not give, as a unified diff without context lines from the replaced `f64` golden to the `f32`
//!   module. Today they are the joint limits (`JOINT_LIMITS` is `[[f64; 2]; N]` whatever the
//!   scalar), one `f64` constant in `lit(10000f64)` and a doc sentence that names both types. By
//!   hand: `sed 's/f64/f32/g' <stem>_f64.rs > /tmp/m.rs && patch /tmp/m.rs <stem>_f32.diff`.
//!
//! Both modules are generated and compared byte for byte with what the files give; a difference
//! is reported with the file, the number of the first differing line and that line on both sides.
//! The diff must also be exactly the one the update below would write (no stale hunk).
//!
//! **Updating (blessing).** When anything differs, the test rewrites `<stem>_f64.rs` and
//! `<stem>_f32.diff` from the generated modules (deleting a diff that became empty, and any file
//! that no longer belongs to a module) and fails. Review `git diff -- codegen/tests/snapshots/shipped`
//! and run `cargo test -p trocar-codegen --test shipped_golden` again: it passes.
//!
//! If the two modules ever differ in line count, the diff is one hunk from the first to the last
//! differing line: still exact, only longer.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use trocar_codegen::{Builder, Real};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn shipped_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/shipped")
}

/// `(file stem, path of the description, is a mechanism)`.
fn sources() -> Vec<(String, PathBuf, bool)> {
    let mut out = Vec::new();
    for dir in [
        "runtime/model/robots",
        "tests/generated/robots",
        "examples/robots",
    ] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        for f in files {
            out.push((
                f.file_stem().unwrap().to_string_lossy().into_owned(),
                f,
                false,
            ));
        }
    }
    // The cooperative arms have a non-square J_Cp: no closed form (tested elsewhere).
    for m in ["four-bar", "planar-stewart"] {
        let p = root().join(format!("runtime/model/robots/mechanisms/{m}.toml"));
        out.push((m.to_string(), p, true));
    }
    out
}

/// The one module generated from a description.
fn generate(path: &Path, mechanism: bool, real: Real) -> String {
    let mut b = Builder::new();
    if mechanism {
        b.mechanism(path);
    } else {
        b.robot(path);
    }
    let modules = b
        .real(real)
        .emit_rerun_if_changed(false)
        .generate()
        .unwrap();
    assert_eq!(modules.len(), 1, "{}", path.display());
    modules.into_values().next().unwrap()
}

/// The `f32` module as the `f64` one predicts it: every `f64` written `f32`.
fn mapped(f64_module: &str) -> String {
    f64_module.replace("f64", "f32")
}

/// The lines of a text split at `'\n'`: the last is what follows the last newline (`""` when the
/// text ends with one), so joining them with `'\n'` gives the text back byte for byte.
fn lines(text: &str) -> Vec<&str> {
    text.split('\n').collect()
}

/// The unified diff (no context lines) from `base` to `target`: empty when they are equal. Lines
/// changed in place become hunks of equal length; when the line counts differ, one hunk spans the
/// first to the last differing line.
fn unified_diff(base_name: &str, target_name: &str, base: &str, target: &str) -> String {
    let (a, b) = (lines(base), lines(target));
    // (index of the first line in `a`, lines of `a` replaced, lines of `b` put instead)
    let mut hunks: Vec<(usize, &[&str], &[&str])> = Vec::new();
    if a.len() == b.len() {
        let mut i = 0;
        while i < a.len() {
            if a[i] == b[i] {
                i += 1;
                continue;
            }
            let start = i;
            while i < a.len() && a[i] != b[i] {
                i += 1;
            }
            hunks.push((start, &a[start..i], &b[start..i]));
        }
    } else {
        let prefix = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
        let room = a.len().min(b.len()) - prefix;
        let suffix = a
            .iter()
            .rev()
            .zip(b.iter().rev())
            .take(room)
            .take_while(|(x, y)| x == y)
            .count();
        hunks.push((
            prefix,
            &a[prefix..a.len() - suffix],
            &b[prefix..b.len() - suffix],
        ));
    }
    if hunks.is_empty() {
        return String::new();
    }
    let mut out = format!("--- {base_name}\n+++ {target_name}\n");
    // Line numbers are 1-based; a side with no lines names the line after which the other's go.
    let header = |at: usize, n: usize| if n == 0 { at } else { at + 1 };
    let mut shift = 0isize; // lines of `b` minus lines of `a` before this hunk
    for (at, old, new) in hunks {
        let at_b = at.checked_add_signed(shift).unwrap();
        out += &format!(
            "@@ -{},{} +{},{} @@\n",
            header(at, old.len()),
            old.len(),
            header(at_b, new.len()),
            new.len()
        );
        for l in old {
            out += &format!("-{l}\n");
        }
        for l in new {
            out += &format!("+{l}\n");
        }
        shift += new.len() as isize - old.len() as isize;
    }
    out
}

/// Applies a diff written by [`unified_diff`] to `base`; an error when it does not apply (a hunk's
/// `-` lines are not those of `base` there) or is not well formed.
fn apply(base: &str, diff: &str) -> Result<String, String> {
    let base = lines(base);
    let mut out: Vec<&str> = Vec::new();
    let mut next = 0; // first line of `base` not yet copied
    let mut diff_lines = diff.split_terminator('\n').enumerate();
    while let Some((n, line)) = diff_lines.next() {
        if line.starts_with("--- ") || line.starts_with("+++ ") {
            continue; // file names
        }
        let bad = |why: &str| format!("diff line {}: {why}: {line}", n + 1);
        let counts = line
            .strip_prefix("@@ -")
            .and_then(|l| l.strip_suffix(" @@"))
            .and_then(|l| l.split_once(" +"))
            .ok_or_else(|| bad("expected a hunk header `@@ -l,n +l,n @@`"))?;
        let parse = |side: &str| -> Option<(usize, usize)> {
            let (at, n) = side.split_once(',')?;
            Some((at.parse().ok()?, n.parse().ok()?))
        };
        let ((at, old_n), (_, new_n)) = parse(counts.0)
            .zip(parse(counts.1))
            .ok_or_else(|| bad("expected a hunk header `@@ -l,n +l,n @@`"))?;
        let at = if old_n == 0 { at } else { at - 1 };
        if at < next || at + old_n > base.len() {
            return Err(bad("hunk out of order or past the end of the golden file"));
        }
        out.extend_from_slice(&base[next..at]);
        for (k, want) in base[at..at + old_n].iter().enumerate() {
            match diff_lines.next() {
                Some((_, l)) if l.strip_prefix('-') == Some(*want) => {}
                Some((m, l)) => {
                    return Err(format!(
                        "diff line {}: does not apply: line {} of the mapped golden is\n  {want}\nthe diff removes\n  {}",
                        m + 1,
                        at + k + 1,
                        l.get(1..).unwrap_or(l)
                    ))
                }
                None => return Err(bad("hunk cut short")),
            }
        }
        for _ in 0..new_n {
            match diff_lines.next() {
                Some((_, l)) if l.starts_with('+') => out.push(&l[1..]),
                _ => return Err(bad("hunk cut short")),
            }
        }
        next = at + old_n;
    }
    out.extend_from_slice(&base[next..]);
    Ok(out.join("\n"))
}

/// `None` when equal, else the first differing line (1-based) on both sides.
fn first_difference(golden: &str, generated: &str) -> Option<String> {
    if golden == generated {
        return None;
    }
    let (g, n) = (lines(golden), lines(generated));
    let i = (0..).find(|&i| g.get(i) != n.get(i)).unwrap();
    let show = |l: Option<&&str>| l.map_or("(end of file)".to_string(), |l| format!("|{l}"));
    Some(format!(
        "first difference at line {} (golden {} lines, generated {}):\n  golden:    {}\n  generated: {}",
        i + 1,
        g.len(),
        n.len(),
        show(g.get(i)),
        show(n.get(i))
    ))
}

/// The `f32` diff file of a pair (empty: no file).
fn f32_record(stem: &str, f64_module: &str, f32_module: &str) -> String {
    unified_diff(
        &format!("{stem}_f64.rs with every f64 written f32"),
        &format!("{stem} f32 module"),
        &mapped(f64_module),
        f32_module,
    )
}

/// What differs between a generated pair and its stored record (`golden`: the `f64` file,
/// `diff`: the `f32` diff, `""` for a missing file); empty when both modules match byte for byte.
fn check(stem: &str, f64_module: &str, f32_module: &str, golden: &str, diff: &str) -> Vec<String> {
    let mut problems = Vec::new();
    if let Some(d) = first_difference(golden, f64_module) {
        problems.push(format!("{stem}_f64.rs: f64 module, {d}"));
    }
    match apply(&mapped(golden), diff) {
        Ok(expected) => {
            if let Some(d) = first_difference(&expected, f32_module) {
                let patched = if diff.is_empty() {
                    "(no diff file)".to_string()
                } else {
                    format!("patched by {stem}_f32.diff")
                };
                problems.push(format!(
                    "{stem}_f64.rs mapped to f32, {patched}: f32 module, {d}"
                ));
            }
        }
        Err(e) => problems.push(format!("{stem}_f32.diff: {e}")),
    }
    if problems.is_empty() && diff != f32_record(stem, golden, f32_module) {
        problems.push(format!(
            "{stem}_f32.diff: gives the f32 module but is not the diff the update writes (a hunk that changes nothing?)"
        ));
    }
    problems
}

#[test]
fn every_shipped_module_matches_its_golden_file() {
    let dir = shipped_dir();
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap_or_default();
    let mut problems = Vec::new();
    let mut kept = BTreeSet::new();
    for (stem, path, mechanism) in sources() {
        let f64_module = generate(&path, mechanism, Real::F64);
        let f32_module = generate(&path, mechanism, Real::F32);
        let (golden_name, diff_name) = (format!("{stem}_f64.rs"), format!("{stem}_f32.diff"));
        let found = check(
            &stem,
            &f64_module,
            &f32_module,
            &read(&golden_name),
            &read(&diff_name),
        );
        let record = f32_record(&stem, &f64_module, &f32_module);
        kept.insert(golden_name.clone());
        if !record.is_empty() {
            kept.insert(diff_name.clone());
        }
        if found.is_empty() {
            continue;
        }
        // Bless: the new record must give the generated pair back.
        assert_eq!(
            apply(&mapped(&f64_module), &record).as_deref(),
            Ok(f32_module.as_str()),
            "{stem}: the diff written does not give the f32 module back"
        );
        std::fs::write(dir.join(&golden_name), &f64_module).unwrap();
        if record.is_empty() {
            let _ = std::fs::remove_file(dir.join(&diff_name));
        } else {
            std::fs::write(dir.join(&diff_name), &record).unwrap();
        }
        problems.extend(found);
    }
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if !kept.contains(&name) {
            std::fs::remove_file(dir.join(&name)).unwrap();
            problems.push(format!("{name}: belongs to no generated module; removed"));
        }
    }
    assert!(
        problems.is_empty(),
        "{}\n\nThe golden files have been rewritten from the generated modules: review \
         `git diff -- codegen/tests/snapshots/shipped` and re-run the test.",
        problems.join("\n\n")
    );
}

/// The check is byte for byte on both modules: generated text changed on one line (of either
/// module, on a line the mapping explains or on one of the diff's, by a character, a line less, a
/// scalar type or the final newline) fails, naming that line.
#[test]
fn a_changed_line_of_either_module_fails_the_check() {
    let path = root().join("examples/robots/ur5_trocar.toml");
    let f64_module = generate(&path, false, Real::F64);
    let f32_module = generate(&path, false, Real::F32);
    let diff = f32_record("ur5", &f64_module, &f32_module);
    assert!(diff.contains("JOINT_LIMITS"), "{diff}");
    assert_eq!(
        check("ur5", &f64_module, &f32_module, &f64_module, &diff),
        Vec::<String>::new()
    );

    // Replaces line `k` (1-based) of a module.
    let edit = |text: &str, k: usize, f: &dyn Fn(&str) -> Option<String>| -> String {
        let mut ls: Vec<String> = lines(text).into_iter().map(String::from).collect();
        match f(&ls[k - 1]) {
            Some(l) => ls[k - 1] = l,
            None => {
                ls.remove(k - 1);
            }
        }
        ls.join("\n")
    };
    let line_of =
        |text: &str, needle: &str| lines(text).iter().position(|l| l.contains(needle)).unwrap() + 1;
    let middle = lines(&f32_module).len() / 2;
    let limits = line_of(&f32_module, "JOINT_LIMITS") + 1; // a joint's limits: a diff line
    let typed = line_of(&f32_module, "<f32 as ::trocar::emitted::Real>"); // a line the mapping explains
    let fails_at = |f64_m: &str, f32_m: &str, module: &str, k: usize| {
        let problems = check("ur5", f64_m, f32_m, &f64_module, &diff);
        assert!(
            problems.iter().any(
                |p| p.contains(module) && p.contains(&format!("first difference at line {k} "))
            ),
            "{module} line {k}: {problems:#?}"
        );
    };
    let space = |l: &str| Some(format!("{l} "));
    // One character more, on the first, a middle and the last line of each module.
    for k in [1, middle, lines(&f64_module).len()] {
        fails_at(&edit(&f64_module, k, &space), &f32_module, "f64 module", k);
    }
    for k in [1, middle, lines(&f32_module).len()] {
        fails_at(&f64_module, &edit(&f32_module, k, &space), "f32 module", k);
    }
    // The same change in both modules.
    let both = |l: &str| Some(l.replace("::trocar::emitted::Real", "::trocar::emitted::Arith"));
    fails_at(
        &edit(&f64_module, typed, &both),
        &edit(&f32_module, typed, &both),
        "f64 module",
        typed,
    );
    // A line the diff holds, written as the mapping would give it.
    let as_mapped = |l: &str| Some(l.replace("f64", "f32"));
    fails_at(
        &f64_module,
        &edit(&f32_module, limits, &as_mapped),
        "f32 module",
        limits,
    );
    // The scalar type itself on a line the mapping explains.
    let as_f64 = |l: &str| Some(l.replace("f32", "f64"));
    fails_at(
        &f64_module,
        &edit(&f32_module, typed, &as_f64),
        "f32 module",
        typed,
    );
    // A line less: one that differs from the line after it (removing one of two equal lines
    // shows first where the copies end).
    let f32_lines = lines(&f32_module);
    let removed = (middle..f32_lines.len())
        .find(|&k| f32_lines[k - 1] != f32_lines[k])
        .unwrap();
    fails_at(
        &f64_module,
        &edit(&f32_module, removed, &|_| None),
        "f32 module",
        removed,
    );
    // The final newline.
    let last = lines(&f64_module).len();
    let cut = f64_module.strip_suffix('\n').unwrap();
    fails_at(cut, &f32_module, "f64 module", last);
    // A diff that names a line the golden does not have is reported, not applied.
    let stale = diff.replacen("-    pub const JOINT_LIMITS", "-    pub const LIMITS", 1);
    let problems = check("ur5", &f64_module, &f32_module, &f64_module, &stale);
    assert!(
        problems.iter().any(|p| p.contains("does not apply")),
        "{problems:#?}"
    );
    // A hunk that changes nothing is refused too (the diff holds only what the mapping misses).
    let end = last - 1; // the module's closing brace, after every hunk
    let noop = format!("{diff}@@ -{end},1 +{end},1 @@\n-}}\n+}}\n");
    let problems = check("ur5", &f64_module, &f32_module, &f64_module, &noop);
    assert!(
        problems
            .iter()
            .any(|p| p.contains("not the diff the update writes")),
        "{problems:#?}"
    );
}

/// The diff gives its target back, for lines changed in place, inserted, removed, at either end
/// and with or without a final newline.
#[test]
fn the_diff_round_trips() {
    let base = "a\nb\nc\nd\ne\n";
    for target in [
        "a\nb\nc\nd\ne\n",
        "a\nB\nc\nD\ne\n",
        "A\nb\nc\nd\nE\n",
        "a\nb\nc\nd\ne",
        "a\nb\nx\ny\nc\nd\ne\n",
        "a\ne\n",
        "z\na\nb\nc\nd\ne\n",
        "a\nb\nc\nd\ne\nf\n",
        "",
        "\n",
    ] {
        let diff = unified_diff("base", "target", base, target);
        assert_eq!(diff.is_empty(), base == target, "{target:?}");
        assert_eq!(apply(base, &diff).as_deref(), Ok(target), "{diff}");
    }
    assert_eq!(
        unified_diff("base", "target", base, "a\nB\nC\nd\nE\n"),
        "--- base\n+++ target\n@@ -2,2 +2,2 @@\n-b\n-c\n+B\n+C\n@@ -5,1 +5,1 @@\n-e\n+E\n"
    );
}
