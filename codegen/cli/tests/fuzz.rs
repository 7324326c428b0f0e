//! Fuzzing of the `trocar` command line (stable Rust, proptest): descriptions (TOML and URDF)
//! and command-line values are generated and mutated, every case runs the built binary in a
//! child process with a 10 s time limit, and each case must end in a clean error or a finite
//! result, never a panic:
//!
//! - the process is not killed by a signal (abort, stack overflow) and its exit code is 0, 1 or
//!   2;
//! - stderr never says `panicked`;
//! - it ends within 10 s (a case that does not is killed and run once more with 60 s, a loaded
//!   machine's margin, and counted as a hang when it does not end then either);
//! - with exit code 0 the answer (stdout, the written files, and stderr: `simulate`'s
//!   summary, `eval`'s notes) holds no `NaN`, `inf` or `null` number: JSON parses and has no
//!   `null`, matrices and CSV cells are finite numbers, generated Rust parses and has no
//!   non-finite literal (nor `NAN`, `INFINITY`), and no word of the other text reads as a
//!   non-finite number;
//! - the files the command was asked to write exist whole after exit code 0 and not after a
//!   failure, and no other file (a temporary one) is left in the working directory.
//!
//! `cargo test -p trocar-cli --test fuzz` runs a bounded number of cases (CI); a failing case is
//! shrunk by proptest and saved as a reproducer. Failures already reported and not yet fixed are
//! listed in [`KNOWN_FINDINGS`]: they are counted apart and do not fail a run
//! (`TROCAR_FUZZ_STRICT=1` ignores the list). The long run is ignored by default:
//! `cargo test -p trocar-cli --test fuzz -- --ignored --nocapture` (see docs/RELIABILITY.md).
//! Environment: `TROCAR_FUZZ_CASES` (long run, default 100000), `TROCAR_FUZZ_CI_CASES` (each CI
//! test), `TROCAR_FUZZ_WORKERS` (1 or 2, default 2), `TROCAR_FUZZ_SEED` (default 1),
//! `TROCAR_FUZZ_FAILURES` (where reproducers go, default `$CARGO_TARGET_TMPDIR/fuzz-failures`),
//! `TROCAR_FUZZ_VERBOSE` (print every case).
#![cfg(unix)]

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};
use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsStr;
use std::fmt;
use std::fs;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// A case that runs longer is killed and run once more with [`RERUN_TIMEOUT`].
const TIMEOUT: Duration = Duration::from_secs(10);

/// The time limit of the second run of a case that timed out: a case that does not end within
/// it is counted as a hang. Wall time, so generous: on two cores shared with other builds (load
/// 10 to 12) cases of 0.5 s of CPU took more than 10 s twice.
const RERUN_TIMEOUT: Duration = Duration::from_secs(60);

// ---------------------------------------------------------------------------------------------
// Value pools
// ---------------------------------------------------------------------------------------------

/// Numbers at the edges, as text: zeros, subnormals, the largest doubles, overflow, NaN and
/// infinity spellings, huge and negative integers, and malformed numbers.
const NUMS: &[&str] = &[
    "0",
    "-0",
    "0.0",
    "-0.0",
    "1",
    "-1",
    "2",
    "6",
    "7",
    "8",
    "9",
    "100",
    "1e-320",
    "-1e-320",
    "5e-324",
    "2.2250738585072014e-308",
    "1e-300",
    "1e-9",
    "1e9",
    "1e15",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e309",
    "-1e309",
    "nan",
    "NaN",
    "+nan",
    "inf",
    "-inf",
    "+inf",
    "infinity",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551616",
    "123456789012345678901234567890",
    "3.141592653589793",
    "-3.141592653589793",
    "1.5707963267948966",
    "6.283185307179586",
    "0.5",
    "1e-5",
    "0x10",
    "1_000",
    "1e",
    "--1",
    ".5",
    "5.",
];

/// Numbers the number rule (`trocar_model::validity`: finite, not subnormal, within ±1e6)
/// accepts, at its edges: overflow and underflow happen inside the computation.
const ALLOWED_EDGES: &[&str] = &[
    "2.2250738585072014e-308",
    "-2.2250738585072014e-308",
    "1e-307",
    "1e-300",
    "1e-200",
    "1e-150",
    "1e-100",
    "1e-12",
    "1e-6",
    "1e5",
    "1e6",
    "-1e6",
    "999999.999",
    "-999999.999",
];

/// Command-line values that are not numbers.
const GARBAGE: &[&str] = &[
    "", " ", "abc", "1,,2", "0.0.0", "½", "١", "+", "-", "--", "NaN(1)", "1 2", "∞", "0b101",
];

/// Joint angles where the kinematics are singular or on a boundary.
const ANGLES: &[&str] = &[
    "0",
    "-0",
    "3.141592653589793",
    "-3.141592653589793",
    "1.5707963267948966",
    "6.283185307179586",
    "0.7227",
    "2.2784",
];

/// Strings for quoted values: names, selections, expressions (division by zero, overflow,
/// unknown names, deep nesting), paths.
fn quoted_pool() -> Vec<String> {
    let mut v: Vec<String> = [
        "",
        " ",
        "x",
        "y",
        "z",
        "rx",
        "rz",
        "zy",
        "zx",
        "xx",
        "revolute",
        "prismatic",
        "fixed",
        "continuous",
        "floating",
        "torso",
        "l_a",
        "l_b",
        "l_zz",
        "l_a/0",
        "1/0",
        "0/0",
        "l_a*1e308*1e308",
        "1e308*10",
        "sqrt(-1)",
        "-l_a",
        "l_a - l_a",
        "pi",
        "-2/3*pi",
        "l_a/(l_b-l_b)",
        "1e-320/1e308",
        "exp(1000)",
        "log(0)",
        "(",
        "l_a +",
        "2^2000",
        "((((((((((1))))))))))",
        "nan",
        "inf",
        "é",
        "a\\\"b",
        "\\",
        "urdf/panda.urdf",
        "urdf/iiwa14.urdf",
        "nope.urdf",
        "/dev/null",
        ".",
        "panda_link3",
        "panda_link8",
        "iiwa_link_6",
        "iiwa_link_ee",
        "chain1",
        "theta1",
        "phi",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    v.push("(".repeat(20_000) + "1" + &")".repeat(20_000));
    v.push("-".repeat(20_000) + "1");
    v.push("a".repeat(10_000));
    v
}

/// Whole TOML values for `key = value` lines.
const TOML_VALUES: &[&str] = &[
    "[]",
    "[0]",
    "[0, 0]",
    "[0, 0, 0, 0]",
    "[1e308, 1e308, 1e308]",
    "[\"nan\", 0, 0]",
    "[0, 0, \"l_a/0\"]",
    "[nan, 0, 0]",
    "[\"x\", \"x\"]",
    "[\"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\"]",
    "[\"q\"]",
    "[1, 0]",
    "{}",
    "{ x = \"1/0\" }",
    "{ x = 1e308, angle = \"nan\" }",
    "true",
    "false",
    "\"\"",
    "\"l_a/0\"",
    "\"nope\"",
    "-1",
    "0",
    "6",
    "7",
    "99",
    "9223372036854775807",
    "-9223372036854775808",
    "1e309",
    "nan",
    "-inf",
    "1e-320",
    "\"panda_link3\"",
    "\"iiwa_link_ee\"",
    "\"urdf/panda.urdf\"",
    "\"/dev/null\"",
    "\".\"",
    "1979-05-27T07:32:00Z",
];

/// Keys of the description formats.
const KEYS: &[&str] = &[
    "link", "xyz", "axis", "h", "wrist", "type", "select", "l_a", "l_b", "l_8", "l0", "l1", "l",
    "name", "tip", "base", "urdf", "outputs", "active", "limits", "initial", "origin", "x",
    "angle",
];

/// Lines to insert into a TOML description.
const TOML_LINES: &[&str] = &[
    "[constraint]",
    "[[joints]]",
    "[parameters]",
    "[task]",
    "[end_effector]",
    "[robot]",
    "[[chains]]",
    "[[chains.joints]]",
    "link = -1",
    "link = 99",
    "link = 0",
    "link = -9223372036854775808",
    "h = []",
    "h = [\"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\"]",
    "select = []",
    "select = [\"x\", \"x\"]",
    "wrist = \"xx\"",
    "l_a = nan",
    "l_a = 1e308",
    "l_a = -0.0",
    "l_q = 1",
    "type = \"prismatic\"",
    "type = \"fixed\"",
    "axis = [0, 0, 0]",
    "axis = [1e-320, 0, 0]",
    "axis = [1e308, 1e308, 1e308]",
    "xyz = [\"l_a / 0\", 0, 0]",
    "xyz = [\"l_a * 1e308 * 1e308\", 0, 0]",
    "name = \"torso\"",
    "urdf = \"urdf/panda.urdf\"",
    "urdf = \"/dev/null\"",
    "urdf = \"nope.urdf\"",
    "urdf = \".\"",
    "tip = \"panda_link3\"",
    "base = \"panda_link8\"",
    "outputs = []",
    "outputs = [\"nope\"]",
    "active = true",
    "limits = [1, 0]",
    "limits = [nan, 1]",
    "initial = 1e308",
    "origin = { x = \"1/0\" }",
    "tip = { x = \"l\", angle = \"nan\" }",
    "base = { x = 1e308 }",
    "a = 1\na = 2",
    "[constraint]\nlink = 3\nxyz = [0, 0, 0]\nh = [\"x\"]",
    "[task]\nselect = [\"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\", \"x\"]",
    "[[joints]]\nname = \"extra\"\ntype = \"revolute\"\nxyz = [0, 0, 1e308]\naxis = [0, 0, 1]",
];

/// Lines to insert into a URDF document.
const XML_LINES: &[&str] = &[
    "<link name=\"panda_link3\"/>",
    "<link name=\"iiwa_link_2\"/>",
    "<link name=\"l1\"/>",
    "<joint name=\"cycle\" type=\"revolute\"><parent link=\"panda_link8\"/><child link=\"panda_link0\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>",
    "<joint name=\"cycle\" type=\"fixed\"><parent link=\"iiwa_link_ee\"/><child link=\"iiwa_link_0\"/></joint>",
    "<joint name=\"loop\" type=\"continuous\"><parent link=\"l2\"/><child link=\"l1\"/></joint>",
    "<joint name=\"self\" type=\"fixed\"><parent link=\"l1\"/><child link=\"l1\"/></joint>",
    "<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>",
    "<mimic joint=\"panda_joint1\"/>",
    "<mimic joint=\"nope\" multiplier=\"nan\"/>",
    "<axis xyz=\"0 0 0\"/>",
    "<axis xyz=\"nan 0 0\"/>",
    "<origin xyz=\"1e308 1e308 1e308\" rpy=\"nan 0 0\"/>",
    "<origin xyz=\"1 2\"/>",
    "<limit lower=\"1\" upper=\"-1\" effort=\"0\" velocity=\"0\"/>",
    "<!--",
    "-->",
    "<![CDATA[",
    "<robot name=\"again\">",
    "</robot>",
    "&amp;",
    "&bogus;",
    "<!DOCTYPE r [<!ENTITY a \"aaaaaaaaaa\"><!ENTITY b \"&a;&a;&a;&a;&a;&a;&a;&a;\"><!ENTITY c \"&b;&b;&b;&b;&b;&b;&b;&b;\">]>",
    "<link name=\"&c;\"/>",
    "<?xml version=\"1.0\"?>",
    "<joint name=\"float\" type=\"floating\"><parent link=\"l0\"/><child link=\"lx\"/></joint>",
];

/// Byte strings to insert anywhere: invalid UTF-8, NUL, a byte-order mark, syntax characters.
const BYTES: &[&[u8]] = &[
    b"\xff",
    b"\xc3\x28",
    b"\xe2\x82",
    b"\x00",
    "\u{feff}".as_bytes(),
    b"\r",
    b"\t",
    b"\"",
    b"'",
    b"[",
    b"]",
    b"=",
    b"<",
    b">",
    b"/>",
    b"#",
    b"'''",
    b"\"\"\"",
    b"\n[[joints]]\n",
    b"\n",
];

/// `--what` values.
const WHATS: &[&str] = &[
    "jr", "manip", "task", "jc", "jb0i", "jb0e", "fk", "passive", "det",
];

/// Simulation scenarios that run in well under a second.
const SHORT_SCENARIOS: &[&str] = &[
    "exp421",
    "panda-laparoscope",
    "four-bar",
    "four-bar-sine",
    "stewart",
    "cooperative",
    "cooperative-gripped",
];

/// Tokens of free-form command lines.
const ARG_TOKENS: &[&[u8]] = &[
    b"generate",
    b"eval",
    b"verify",
    b"jacobian",
    b"simulate",
    b"preset",
    b"help",
    b"--help",
    b"-h",
    b"--version",
    b"-V",
    b"--q",
    b"--q=",
    b"--q=0",
    b"--param",
    b"--what",
    b"--json",
    b"--numeric",
    b"--samples",
    b"--seed",
    b"--urdf",
    b"--tip",
    b"--frame",
    b"--real",
    b"-o",
    b"--method",
    b"--csv",
    b"--plot",
    b"--drift-correction",
    b"--max-joint-speed",
    b"bidirectional-zy",
    b"four-bar",
    b"panda-laparoscope",
    b"exp421",
    b"/",
    b".",
    b"",
    b"-",
    b"--",
    b"\xff\xfe",
    b"0",
    b"nan",
    b"-1",
];

// ---------------------------------------------------------------------------------------------
// The shipped inputs
// ---------------------------------------------------------------------------------------------

/// A shipped TOML description: its text, joint count and parameters, and the URDF it reads.
struct TomlBase {
    file: String,
    text: String,
    joints: usize,
    params: Vec<String>,
    /// `(path as written in the description, text)`.
    urdf: Option<(String, String)>,
}

/// A shipped URDF: its text, its link and joint names, and the joint count to each link.
struct UrdfBase {
    path: PathBuf,
    text: String,
    names: Vec<String>,
    joints: Vec<String>,
    tips: Vec<(String, usize)>,
}

/// A description the command line knows by name or path.
#[derive(Clone, Debug)]
struct Named {
    name: String,
    joints: usize,
    params: Vec<String>,
}

struct Bases {
    tomls: Vec<TomlBase>,
    urdfs: Vec<UrdfBase>,
    named: Vec<Named>,
}

fn robots_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/robots")
}

/// The joint count an error message states (`… has 8 joints …`), or 1 when `--q=0` was accepted.
fn probe_joints(args: &[&OsStr], dir: &Path) -> usize {
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .arg("--q=0")
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .expect("the trocar binary runs");
    if out.status.code() == Some(0) {
        return 1;
    }
    let err = String::from_utf8_lossy(&out.stderr);
    for (at, _) in err.match_indices("has ") {
        let rest = &err[at + 4..];
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        if !digits.is_empty() && rest[digits.len()..].starts_with(" joints") {
            return digits.parse().unwrap_or(1);
        }
    }
    1
}

/// The names declared in the `[parameters]` table of a TOML text.
fn parameter_names(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut inside = false;
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            inside = line == "[parameters]";
        } else if inside {
            if let Some((k, _)) = line.split_once('=') {
                if !k.trim().is_empty() && !k.trim_start().starts_with('#') {
                    names.push(k.trim().to_string());
                }
            }
        }
    }
    names
}

/// The value of `key = "…"` in a TOML text.
fn string_value(text: &str, key: &str) -> Option<String> {
    text.lines().find_map(|l| {
        let (k, v) = l.split_once('=')?;
        (k.trim() == key).then(|| v.trim().split('"').nth(1).map(str::to_string))?
    })
}

/// Values of the attribute `attr` of the elements `tag` of an XML text.
fn xml_names(text: &str, tag: &str, attr: &str) -> Vec<String> {
    let mut v = Vec::new();
    let open = format!("<{tag} ");
    for (at, _) in text.match_indices(&open) {
        let rest = &text[at..];
        let end = rest.find('>').unwrap_or(rest.len());
        let pat = format!("{attr}=\"");
        if let Some(p) = rest[..end].find(&pat) {
            let s = &rest[p + pat.len()..end];
            if let Some(q) = s.find('"') {
                v.push(s[..q].to_string());
            }
        }
    }
    v
}

fn bases() -> &'static Bases {
    static BASES: OnceLock<Bases> = OnceLock::new();
    BASES.get_or_init(|| {
        let dir = robots_dir();
        let mut files: Vec<PathBuf> = Vec::new();
        for d in [dir.clone(), dir.join("mechanisms")] {
            for e in fs::read_dir(&d).expect("the shipped descriptions") {
                let p = e.unwrap().path();
                if p.extension().is_some_and(|x| x == "toml") {
                    files.push(p);
                }
            }
        }
        files.sort();
        let mut tomls = Vec::new();
        let mut named = Vec::new();
        for p in &files {
            let text = fs::read_to_string(p).unwrap();
            let joints = probe_joints(&["eval".as_ref(), p.as_os_str()], &dir);
            let params = parameter_names(&text);
            let urdf = string_value(&text, "urdf").map(|rel| {
                let t = fs::read_to_string(p.parent().unwrap().join(&rel)).unwrap();
                (rel, t)
            });
            named.push(Named {
                name: p.to_string_lossy().into_owned(),
                joints,
                params: params.clone(),
            });
            let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
            let by_name = Named {
                name: stem.clone(),
                joints,
                params: params.clone(),
            };
            if probe_joints(&["eval".as_ref(), stem.as_ref()], Path::new("/")) == joints {
                named.push(by_name);
            }
            tomls.push(TomlBase {
                file: format!("{stem}.toml"),
                text,
                joints,
                params,
                urdf,
            });
        }
        let mut urdfs = Vec::new();
        for e in fs::read_dir(dir.join("urdf")).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_none_or(|x| x != "urdf") {
                continue;
            }
            let text = fs::read_to_string(&p).unwrap();
            let links = xml_names(&text, "link", "name");
            let joints = xml_names(&text, "joint", "name");
            let tips = links
                .iter()
                .map(|l| {
                    let n = probe_joints(
                        &[
                            "jacobian".as_ref(),
                            "--urdf".as_ref(),
                            p.as_os_str(),
                            "--tip".as_ref(),
                            l.as_ref(),
                        ],
                        &dir,
                    );
                    (l.clone(), n)
                })
                .collect();
            let mut names = links.clone();
            names.extend(joints.iter().cloned());
            urdfs.push(UrdfBase {
                path: p,
                text,
                names,
                joints,
                tips,
            });
        }
        urdfs.sort_by(|a, b| a.path.cmp(&b.path));
        assert!(tomls.len() >= 8 && urdfs.len() >= 2 && named.len() >= 15);
        Bases {
            tomls,
            urdfs,
            named,
        }
    })
}

// ---------------------------------------------------------------------------------------------
// Cases
// ---------------------------------------------------------------------------------------------

/// One run of the binary: its arguments, the input files written into a fresh working
/// directory, and the output files the arguments ask for.
#[derive(Clone)]
struct Case {
    /// Where the case comes from: `toml`, `urdf`, `chain`, `cli` or `trajectory`.
    source: &'static str,
    args: Vec<Vec<u8>>,
    files: Vec<(String, Vec<u8>)>,
    outputs: Vec<Vec<u8>>,
}

impl Case {
    fn command(&self) -> &'static str {
        match self.args.first().map(Vec::as_slice) {
            Some(b"generate") => "generate",
            Some(b"eval") => "eval",
            Some(b"verify") => "verify",
            Some(b"jacobian") => "jacobian",
            Some(b"simulate") => "simulate",
            Some(b"preset") => "preset",
            _ => "other",
        }
    }

    /// The command line, quoted for bash.
    fn command_line(&self) -> String {
        let mut s = String::from("trocar");
        for a in &self.args {
            s.push(' ');
            s.push_str(&shell_quote(a));
        }
        s
    }

    /// Whether the arguments ask clap for help or the version (exit code 0 without work).
    fn asks_help(&self) -> bool {
        self.args.iter().any(|a| {
            matches!(
                a.as_slice(),
                b"--help" | b"-h" | b"--version" | b"-V" | b"help"
            )
        })
    }
}

impl fmt::Debug for Case {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "[{}] {}", self.source, self.command_line())?;
        for (name, content) in &self.files {
            let text = String::from_utf8_lossy(content);
            let shown: String = text.chars().take(3000).collect();
            let more = if shown.len() < text.len() {
                "\n…"
            } else {
                ""
            };
            writeln!(f, "--- {name} ({} bytes)\n{shown}{more}", content.len())?;
        }
        Ok(())
    }
}

fn shell_quote(a: &[u8]) -> String {
    let plain = !a.is_empty()
        && a.iter()
            .all(|&b| b.is_ascii_alphanumeric() || b"-_=.,/+:@%".contains(&b));
    if plain {
        return String::from_utf8_lossy(a).into_owned();
    }
    let mut s = String::from("$'");
    for &b in a {
        match b {
            b'\'' => s.push_str("\\'"),
            b'\\' => s.push_str("\\\\"),
            0x20..=0x7e => s.push(b as char),
            _ => s.push_str(&format!("\\x{b:02x}")),
        }
    }
    s.push('\'');
    s
}

fn arg(s: impl AsRef<str>) -> Vec<u8> {
    s.as_ref().as_bytes().to_vec()
}

fn args(v: &[&str]) -> Vec<Vec<u8>> {
    v.iter().map(arg).collect()
}

// ---------------------------------------------------------------------------------------------
// Text mutations
// ---------------------------------------------------------------------------------------------

/// One mutation of a description's bytes.
#[derive(Clone, Debug)]
enum Edit {
    /// Replace one number.
    Number(usize, String),
    /// Replace the contents of one `"…"`.
    Quoted(usize, String),
    /// Replace the value of one `key = …` line with this key.
    SetKey(&'static str, usize, String),
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    /// Swap the keys of two `key = …` lines.
    SwapKeys(usize, usize),
    InsertLine(usize, String),
    Truncate(usize),
    InsertBytes(usize, Vec<u8>),
    /// Remove one `<joint>…</joint>` or `<link …>` element.
    RemoveElement(usize),
    DuplicateElement(usize),
    /// Add a `<mimic>` to one joint.
    Mimic(usize, String, String, String),
}

/// Spans of the numbers of `t` (not the digits inside names such as `panda_link3`).
fn number_spans(t: &[u8]) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let c = t[i];
        let prev_ok = i == 0 || !(t[i - 1].is_ascii_alphanumeric() || b"_.".contains(&t[i - 1]));
        let starts = c.is_ascii_digit()
            || (b"-+.".contains(&c) && t.get(i + 1).is_some_and(u8::is_ascii_digit));
        if prev_ok && starts {
            let s = i;
            i += 1;
            while i < t.len()
                && (t[i].is_ascii_digit()
                    || b"._eE".contains(&t[i])
                    || (b"+-".contains(&t[i]) && b"eE".contains(&t[i - 1])))
            {
                i += 1;
            }
            v.push((s, i));
        } else {
            i += 1;
        }
    }
    v
}

/// Spans of the contents of the `"…"` of `t` (within one line).
fn quoted_spans(t: &[u8]) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut i = 0;
    while i < t.len() {
        if t[i] == b'"' {
            let s = i + 1;
            let mut e = s;
            while e < t.len() && t[e] != b'"' && t[e] != b'\n' {
                e += 1;
            }
            if e < t.len() && t[e] == b'"' {
                v.push((s, e));
                i = e + 1;
                continue;
            }
        }
        i += 1;
    }
    v
}

fn lines(t: &[u8]) -> Vec<Vec<u8>> {
    t.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect()
}

fn join(lines: &[Vec<u8>]) -> Vec<u8> {
    lines.join(&b'\n')
}

/// `(line, key span, value span)` of the `key = value` lines.
/// A byte range `start..end`.
type Span = (usize, usize);

fn key_lines(ls: &[Vec<u8>]) -> Vec<(usize, Span, Span)> {
    let mut v = Vec::new();
    for (k, l) in ls.iter().enumerate() {
        let start = l.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(0);
        let first = l.get(start).copied().unwrap_or(b'#');
        if !(first.is_ascii_alphanumeric() || first == b'_') {
            continue;
        }
        let Some(eq) = l.iter().position(|&b| b == b'=') else {
            continue;
        };
        let mut kend = eq;
        while kend > start && l[kend - 1].is_ascii_whitespace() {
            kend -= 1;
        }
        let vend = l
            .iter()
            .position(|&b| b == b'#')
            .unwrap_or(l.len())
            .max(eq + 1);
        v.push((k, (start, kend), (eq + 1, vend)));
    }
    v
}

/// Spans of the `<joint …>…</joint>` and `<link …/>` / `<link …>…</link>` elements.
fn element_spans(t: &[u8]) -> Vec<(usize, usize)> {
    let find = |from: usize, pat: &[u8]| {
        t[from.min(t.len())..]
            .windows(pat.len())
            .position(|w| w == pat)
            .map(|p| p + from)
    };
    let mut v = Vec::new();
    for (open, close) in [(&b"<joint"[..], &b"</joint>"[..]), (b"<link", b"</link>")] {
        let mut from = 0;
        while let Some(s) = find(from, open) {
            let gt = find(s, b">").unwrap_or(t.len());
            let end = if gt > 0 && t[gt - 1] == b'/' {
                (gt + 1).min(t.len())
            } else {
                find(s, close).map_or(t.len(), |e| e + close.len())
            };
            v.push((s, end));
            from = s + open.len();
        }
    }
    v.sort();
    v
}

/// `i` as a position in a collection of `len > 0` elements.
fn at(i: &usize, len: usize) -> usize {
    i % len
}

fn pick<T: Copy>(v: &[T], i: &usize) -> Option<T> {
    (!v.is_empty()).then(|| v[at(i, v.len())])
}

fn apply(t: &mut Vec<u8>, edit: &Edit) {
    match edit {
        Edit::Number(i, s) => {
            if let Some((a, b)) = pick(&number_spans(t), i) {
                t.splice(a..b, s.bytes());
            }
        }
        Edit::Quoted(i, s) => {
            if let Some((a, b)) = pick(&quoted_spans(t), i) {
                t.splice(a..b, s.bytes());
            }
        }
        Edit::SetKey(key, i, s) => {
            let mut ls = lines(t);
            let hits: Vec<_> = key_lines(&ls)
                .into_iter()
                .filter(|(k, (a, b), _)| &ls[*k][*a..*b] == key.as_bytes())
                .collect();
            if let Some((k, _, (a, b))) = pick(&hits, i) {
                ls[k].splice(a..b, format!(" {s} ").into_bytes());
                *t = join(&ls);
            }
        }
        Edit::DeleteLine(i) => {
            let mut ls = lines(t);
            ls.remove(at(i, ls.len()));
            *t = join(&ls);
        }
        Edit::DuplicateLine(i) => {
            let mut ls = lines(t);
            let k = at(i, ls.len());
            ls.insert(k, ls[k].clone());
            *t = join(&ls);
        }
        Edit::SwapLines(i, j) => {
            let mut ls = lines(t);
            let n = ls.len();
            ls.swap(at(i, n), at(j, n));
            *t = join(&ls);
        }
        Edit::SwapKeys(i, j) => {
            let mut ls = lines(t);
            let kl = key_lines(&ls);
            if let (Some((k1, (a1, b1), _)), Some((k2, (a2, b2), _))) = (pick(&kl, i), pick(&kl, j))
            {
                if k1 != k2 {
                    let key1 = ls[k1][a1..b1].to_vec();
                    let key2 = ls[k2][a2..b2].to_vec();
                    ls[k1].splice(a1..b1, key2);
                    ls[k2].splice(a2..b2, key1);
                    *t = join(&ls);
                }
            }
        }
        Edit::InsertLine(i, s) => {
            let mut ls = lines(t);
            let k = at(i, ls.len() + 1);
            ls.insert(k, s.as_bytes().to_vec());
            *t = join(&ls);
        }
        Edit::Truncate(i) => {
            let k = at(i, t.len() + 1);
            t.truncate(k);
        }
        Edit::InsertBytes(i, b) => {
            let k = at(i, t.len() + 1);
            t.splice(k..k, b.iter().copied());
        }
        Edit::RemoveElement(i) => {
            if let Some((a, b)) = pick(&element_spans(t), i) {
                t.drain(a..b);
            }
        }
        Edit::DuplicateElement(i) => {
            if let Some((a, b)) = pick(&element_spans(t), i) {
                let copy = t[a..b].to_vec();
                t.splice(b..b, copy);
            }
        }
        Edit::Mimic(i, joint, mult, off) => {
            let ends: Vec<usize> = t
                .windows(8)
                .enumerate()
                .filter(|(_, w)| *w == b"</joint>")
                .map(|(k, _)| k)
                .collect();
            if let Some(k) = pick(&ends, i) {
                let m =
                    format!("<mimic joint=\"{joint}\" multiplier=\"{mult}\" offset=\"{off}\"/>");
                t.splice(k..k, m.into_bytes());
            }
        }
    }
}

fn mutate(text: &str, edits: &[Edit]) -> Vec<u8> {
    let mut t = text.as_bytes().to_vec();
    for e in edits {
        apply(&mut t, e);
    }
    t
}

// ---------------------------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------------------------

fn strs(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// A number as text: mostly edge values, some ordinary ones, any double in any class.
fn num() -> BoxedStrategy<String> {
    prop_oneof![
        4 => select(NUMS).prop_map(String::from),
        2 => select(ALLOWED_EDGES).prop_map(String::from),
        2 => (-10.0f64..10.0).prop_map(|v| format!("{v}")),
        1 => any::<i64>().prop_map(|v| v.to_string()),
        1 => any::<f64>().prop_map(|v| format!("{v:e}")),
    ]
    .boxed()
}

/// A parameter value: mostly an ordinary length, sometimes an edge value.
fn param_value() -> BoxedStrategy<String> {
    prop_oneof![
        4 => (0.01f64..2.0).prop_map(|v| format!("{v}")),
        1 => select(ALLOWED_EDGES).prop_map(String::from),
        2 => num(),
        1 => select(GARBAGE).prop_map(String::from),
    ]
    .boxed()
}

/// One joint value: an ordinary angle, or a singular one.
fn angle() -> BoxedStrategy<String> {
    prop_oneof![
        8 => (-3.5f64..3.5).prop_map(|v| format!("{v}")),
        2 => select(ANGLES).prop_map(String::from),
    ]
    .boxed()
}

/// A `--q` list of about `n` values: all ordinary, one edge or garbage value among ordinary
/// ones, or any value anywhere; sometimes a wrong length.
fn q_list(n: usize) -> BoxedStrategy<String> {
    let len = prop_oneof![
        12 => Just(n),
        1 => 0..=n.saturating_sub(1),
        1 => (n + 1)..=(n + 3),
        1 => Just(64usize),
    ];
    let odd = prop_oneof![
        5 => select(NUMS).prop_map(String::from),
        3 => select(ALLOWED_EDGES).prop_map(String::from),
        1 => select(GARBAGE).prop_map(String::from),
    ];
    let any_value = prop_oneof![5 => angle(), 2 => odd.clone()];
    len.prop_flat_map(move |k| {
        prop_oneof![
            8 => vec(angle(), k),
            2 => (vec(angle(), k), any::<usize>(), odd.clone()).prop_map(|(mut v, i, o)| {
                if !v.is_empty() {
                    let k = at(&i, v.len());
                    v[k] = o;
                }
                v
            }),
            1 => vec(any_value.clone(), k),
        ]
    })
    .prop_map(|v| v.join(","))
    .boxed()
}

/// `--q` arguments: `--q=LIST`, `--q LIST`, twice, or with invalid UTF-8.
fn q_args(n: usize) -> BoxedStrategy<Vec<Vec<u8>>> {
    prop_oneof![
        12 => q_list(n).prop_map(|l| vec![arg(format!("--q={l}"))]),
        6 => q_list(n).prop_map(|l| vec![arg("--q"), arg(l)]),
        1 => (q_list(n / 2), q_list(n - n / 2))
            .prop_map(|(a, b)| vec![arg("--q"), arg(a), arg(format!("--q={b}"))]),
        1 => Just(vec![b"--q=0,\xff".to_vec()]),
    ]
    .boxed()
}

/// `--param name=value` arguments.
fn param_args(params: &[String]) -> BoxedStrategy<Vec<Vec<u8>>> {
    let bad = strs(&["nope", "", " l_a ", "L_A", "l_a=1"]);
    let names = if params.is_empty() {
        select(bad).boxed()
    } else {
        prop_oneof![6 => select(params.to_vec()), 1 => select(bad)].boxed()
    };
    let one = (names, param_value(), 0..12u8).prop_map(|(n, v, form)| match form {
        0 => vec![arg("--param"), arg(&n)],
        1 => vec![arg("--param"), arg(format!("={v}"))],
        2 => vec![arg(format!("--param={n}={v}"))],
        _ => vec![arg("--param"), arg(format!("{n}={v}"))],
    });
    prop_oneof![
        3 => Just(Vec::new()),
        2 => vec(one, 1..3).prop_map(|v| v.concat()),
    ]
    .boxed()
}

/// An optional `--flag value`.
fn opt(
    flag: &'static str,
    values: BoxedStrategy<String>,
    weight_none: u32,
) -> BoxedStrategy<Vec<Vec<u8>>> {
    prop_oneof![
        weight_none => Just(Vec::new()),
        1 => values.prop_map(move |v| vec![arg(flag), arg(v)]),
    ]
    .boxed()
}

/// Mostly one of `valid`, sometimes one of `bad`.
fn choice(valid: &[&str], bad: &[&str]) -> BoxedStrategy<String> {
    prop_oneof![8 => select(strs(valid)), 1 => select(strs(bad))].boxed()
}

fn flag(name: &'static str) -> BoxedStrategy<Vec<Vec<u8>>> {
    prop_oneof![Just(Vec::new()), Just(vec![arg(name)])].boxed()
}

fn what() -> BoxedStrategy<String> {
    prop_oneof![
        8 => select(WHATS).prop_map(String::from),
        1 => select(strs(&["JR", "", "x", "--json", "all", "fk,jb0i", "jr,jr", "fk,", "manip,jr,fk0i"])),
    ]
    .boxed()
}

/// The arguments of `eval` after the description.
fn eval_tail(n: usize, params: &[String]) -> BoxedStrategy<Vec<Vec<u8>>> {
    (
        q_args(n),
        param_args(params),
        opt("--what", what(), 1),
        flag("--json"),
        flag("--numeric"),
    )
        .prop_map(|(q, p, w, j, nu)| [q, p, w, j, nu].concat())
        .boxed()
}

/// The arguments of `verify` after the description: few samples (the default is 1000).
fn verify_tail() -> BoxedStrategy<Vec<Vec<u8>>> {
    let samples = prop_oneof![
        8 => (1..40u32).prop_map(|v| v.to_string()),
        1 => select(strs(&[
            "0", "-1", "abc", "", "1e3", "18446744073709551616", "2000", "200",
        ])),
    ];
    let seed = select(strs(&[
        "0",
        "1",
        "42",
        "18446744073709551615",
        "-1",
        "x",
        "18446744073709551616",
    ]));
    (samples, opt("--seed", seed.boxed(), 2))
        .prop_map(|(s, seed)| [vec![arg("--samples"), arg(s)], seed].concat())
        .boxed()
}

/// The arguments of `generate` after the description, the outputs they name, and the input
/// files they need (a directory for `sub/out.rs`).
type Tail = (Vec<Vec<u8>>, Vec<Vec<u8>>, Vec<(String, Vec<u8>)>);

fn generate_tail() -> BoxedStrategy<Tail> {
    let real = choice(&["generic", "f32", "f64"], &["F32", "f16", ""]);
    let out = prop_oneof![
        6 => Just(None),
        3 => Just(Some(&b"out.rs"[..])),
        1 => Just(Some(&b"sub/out.rs"[..])),
        1 => Just(Some(&b"out\xff.rs"[..])),
        1 => select(vec![
            &b"nodir/x.rs"[..], b"", b".", b"..", b"/", b"out.rs/", b"sub", b"robot.toml/x",
        ]).prop_map(Some),
    ];
    (opt("--real", real, 2), out)
        .prop_map(|(r, o)| {
            let mut a = r;
            let mut outputs = Vec::new();
            let files = vec![("sub/.keep".to_string(), Vec::new())];
            if let Some(o) = o {
                a.push(arg("-o"));
                a.push(o.to_vec());
                if [&b"out.rs"[..], b"sub/out.rs", b"out\xff.rs"].contains(&o) {
                    outputs.push(o.to_vec());
                }
            }
            (a, outputs, files)
        })
        .boxed()
}

/// A command on a description file (`generate`, `eval` or `verify`).
fn description_command(file: String, n: usize, params: Vec<String>) -> BoxedStrategy<Tail> {
    let f1 = file.clone();
    let f2 = file.clone();
    prop_oneof![
        3 => generate_tail().prop_map(move |(a, o, fs)| {
            ([vec![arg("generate"), arg(&f1)], a].concat(), o, fs)
        }),
        5 => eval_tail(n, &params).prop_map(move |a| {
            ([vec![arg("eval"), arg(&f2)], a].concat(), Vec::new(), Vec::new())
        }),
        2 => verify_tail().prop_map(move |a| {
            ([vec![arg("verify"), arg(&file)], a].concat(), Vec::new(), Vec::new())
        }),
    ]
    .boxed()
}

fn toml_edit(names: Vec<String>) -> BoxedStrategy<Edit> {
    let mut quoted = quoted_pool();
    quoted.extend(names);
    let value = prop_oneof![
        3 => num(),
        2 => select(TOML_VALUES).prop_map(String::from),
        1 => select(quoted.clone()).prop_map(|s| format!("\"{s}\"")),
    ];
    prop_oneof![
        5 => (any::<usize>(), num()).prop_map(|(i, v)| Edit::Number(i, v)),
        3 => (any::<usize>(), (-3.0f64..3.0).prop_map(|v| format!("{v}")))
            .prop_map(|(i, v)| Edit::Number(i, v)),
        2 => (any::<usize>(), select(quoted)).prop_map(|(i, s)| Edit::Quoted(i, s)),
        4 => (select(KEYS), any::<usize>(), value).prop_map(|(k, i, v)| Edit::SetKey(k, i, v)),
        1 => any::<usize>().prop_map(Edit::DeleteLine),
        1 => any::<usize>().prop_map(Edit::DuplicateLine),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Edit::SwapLines(i, j)),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Edit::SwapKeys(i, j)),
        2 => (any::<usize>(), select(TOML_LINES).prop_map(String::from))
            .prop_map(|(i, s)| Edit::InsertLine(i, s)),
        1 => any::<usize>().prop_map(Edit::Truncate),
        1 => (any::<usize>(), select(BYTES)).prop_map(|(i, b)| Edit::InsertBytes(i, b.to_vec())),
    ]
    .boxed()
}

fn xml_edit(names: Vec<String>, joints: Vec<String>) -> BoxedStrategy<Edit> {
    let mut quoted = strs(&[
        "",
        " ",
        "world",
        "nope",
        "revolute",
        "prismatic",
        "fixed",
        "continuous",
        "floating",
        "planar",
        "0 0 0",
        "nan 0 0",
        "1 2",
        "1e308 1e308 1e308",
        "0 0 1e-320",
        "a b c",
    ]);
    quoted.extend(names);
    let mut mimic_targets = joints;
    mimic_targets.extend(strs(&["nope", ""]));
    let nested = "<a>".repeat(20_000) + &"</a>".repeat(20_000);
    let mut xml_lines = strs(XML_LINES);
    xml_lines.push(nested);
    prop_oneof![
        6 => (any::<usize>(), num()).prop_map(|(i, v)| Edit::Number(i, v)),
        3 => (any::<usize>(), (-3.0f64..3.0).prop_map(|v| format!("{v}")))
            .prop_map(|(i, v)| Edit::Number(i, v)),
        3 => (any::<usize>(), select(quoted)).prop_map(|(i, s)| Edit::Quoted(i, s)),
        1 => any::<usize>().prop_map(Edit::DeleteLine),
        1 => any::<usize>().prop_map(Edit::DuplicateLine),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Edit::SwapLines(i, j)),
        2 => (any::<usize>(), select(xml_lines)).prop_map(|(i, s)| Edit::InsertLine(i, s)),
        1 => any::<usize>().prop_map(Edit::Truncate),
        1 => (any::<usize>(), select(BYTES)).prop_map(|(i, b)| Edit::InsertBytes(i, b.to_vec())),
        2 => any::<usize>().prop_map(Edit::RemoveElement),
        1 => any::<usize>().prop_map(Edit::DuplicateElement),
        2 => (any::<usize>(), select(mimic_targets), num(), num())
            .prop_map(|(i, j, m, o)| Edit::Mimic(i, j, m, o)),
    ]
    .boxed()
}

/// Edits: none, or a few.
fn edits(e: BoxedStrategy<Edit>, none: u32) -> BoxedStrategy<Vec<Edit>> {
    prop_oneof![
        none => Just(Vec::new()),
        3 => vec(e.clone(), 1..2),
        2 => vec(e, 2..5),
    ]
    .boxed()
}

/// A mutated shipped TOML description (and the URDF it reads), and a command on it.
fn toml_cases() -> BoxedStrategy<Case> {
    let b = bases();
    let per_base: Vec<BoxedStrategy<Case>> = b
        .tomls
        .iter()
        .map(|t| {
            let mut names = t.params.clone();
            names.extend(["torso", "shaft_7", "tool", "theta1", "phi"].map(String::from));
            let urdf_edits = match &t.urdf {
                Some((_, text)) => {
                    let links = xml_names(text, "link", "name");
                    let joints = xml_names(text, "joint", "name");
                    let mut all = links.clone();
                    all.extend(joints.iter().cloned());
                    names.extend(links);
                    edits(xml_edit(all, joints), 6)
                }
                None => Just(Vec::new()).boxed(),
            };
            let file = t.file.clone();
            let text = t.text.clone();
            let urdf = t.urdf.clone();
            (
                edits(toml_edit(names), 1),
                urdf_edits,
                description_command(t.file.clone(), t.joints, t.params.clone()),
            )
                .prop_map(move |(te, ue, (args, outputs, mut files))| {
                    files.push((file.clone(), mutate(&text, &te)));
                    if let Some((rel, utext)) = &urdf {
                        files.push((rel.clone(), mutate(utext, &ue)));
                    }
                    Case {
                        source: "toml",
                        args,
                        files,
                        outputs,
                    }
                })
                .boxed()
        })
        .collect();
    proptest::strategy::Union::new(per_base).boxed()
}

/// `jacobian --urdf FILE --tip TIP --q …` arguments.
fn jacobian_args(file: String, tips: Vec<(String, usize)>) -> BoxedStrategy<Vec<Vec<u8>>> {
    let mut tip_choices: Vec<(String, usize)> = tips;
    tip_choices.extend([("nope", 7), ("", 7), ("world", 7)].map(|(s, n)| (s.to_string(), n)));
    select(tip_choices)
        .prop_flat_map(move |(tip, n)| {
            let file = file.clone();
            let frame = choice(&["body", "spatial"], &["Body", "world"]);
            (q_args(n), opt("--frame", frame, 1), flag("--json")).prop_map(move |(q, f, j)| {
                [args(&["jacobian", "--urdf", &file, "--tip", &tip]), q, f, j].concat()
            })
        })
        .boxed()
}

/// A mutated shipped URDF and `jacobian` on it.
fn urdf_cases() -> BoxedStrategy<Case> {
    let b = bases();
    let per_base: Vec<BoxedStrategy<Case>> = b
        .urdfs
        .iter()
        .map(|u| {
            let text = u.text.clone();
            // The last link is the usual tip.
            let mut tips = u.tips.clone();
            if let Some(last) = u.tips.last() {
                tips.extend(std::iter::repeat_n(last.clone(), 4));
            }
            (
                edits(xml_edit(u.names.clone(), u.joints.clone()), 1),
                jacobian_args("robot.urdf".into(), tips),
            )
                .prop_map(move |(e, args)| Case {
                    source: "urdf",
                    args,
                    files: vec![("robot.urdf".into(), mutate(&text, &e))],
                    outputs: Vec::new(),
                })
                .boxed()
        })
        .collect();
    proptest::strategy::Union::new(per_base).boxed()
}

/// One joint of a generated chain.
#[derive(Clone, Debug)]
struct JointSpec {
    kind: &'static str,
    xyz: String,
    rpy: String,
    axis: String,
    limit: (String, String),
    parent: Option<usize>,
    child: Option<usize>,
    mimic: Option<(usize, String, String)>,
}

fn coordinate() -> BoxedStrategy<String> {
    prop_oneof![
        8 => (-1.0f64..1.0).prop_map(|v| format!("{v}")),
        1 => Just("0".to_string()),
        1 => num(),
    ]
    .boxed()
}

fn triple() -> BoxedStrategy<String> {
    prop_oneof![
        10 => (coordinate(), coordinate(), coordinate()).prop_map(|(a, b, c)| format!("{a} {b} {c}")),
        1 => select(strs(&["", "1 2", "a b c", "0 0 0 0", "1e308 1e308 1e308", "nan nan nan"])),
    ]
    .boxed()
}

fn joint_spec() -> BoxedStrategy<JointSpec> {
    let kind = prop_oneof![
        6 => Just("revolute"),
        2 => Just("continuous"),
        2 => Just("prismatic"),
        1 => Just("fixed"),
        1 => select(vec!["floating", "planar", "spherical", ""]),
    ];
    let axis = prop_oneof![
        6 => select(strs(&["1 0 0", "0 1 0", "0 0 1", "0 0 -1"])),
        2 => triple(),
        1 => select(strs(&["0 0 0", "1e-320 0 0", "nan 0 0", "1e308 1e308 0", "1 1", ""])),
    ];
    let limit = prop_oneof![
        6 => Just(("-3".to_string(), "3".to_string())),
        1 => (num(), num()),
    ];
    let link = prop_oneof![12 => Just(None), 1 => (0..10usize).prop_map(Some)];
    let mimic = prop_oneof![
        12 => Just(None),
        1 => (0..9usize, num(), num()).prop_map(Some),
    ];
    (
        kind,
        triple(),
        triple(),
        axis,
        limit,
        link.clone(),
        link,
        mimic,
    )
        .prop_map(
            |(kind, xyz, rpy, axis, limit, parent, child, mimic)| JointSpec {
                kind,
                xyz,
                rpy,
                axis,
                limit,
                parent,
                child,
                mimic,
            },
        )
        .boxed()
}

/// The URDF text of a chain `l0 -j1- l1 … -jn- ln` (with the joints' overrides: cycles, unknown
/// links, mimics).
fn chain_urdf(joints: &[JointSpec]) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n<robot name=\"chain\">\n");
    for k in 0..=joints.len() {
        s += &format!("  <link name=\"l{k}\"/>\n");
    }
    for (k, j) in joints.iter().enumerate() {
        let k = k + 1;
        s += &format!("  <joint name=\"j{k}\" type=\"{}\">\n", j.kind);
        s += &format!("    <origin xyz=\"{}\" rpy=\"{}\"/>\n", j.xyz, j.rpy);
        s += &format!(
            "    <parent link=\"l{}\"/>\n    <child link=\"l{}\"/>\n",
            j.parent.unwrap_or(k - 1),
            j.child.unwrap_or(k)
        );
        s += &format!("    <axis xyz=\"{}\"/>\n", j.axis);
        s += &format!(
            "    <limit lower=\"{}\" upper=\"{}\" effort=\"10\" velocity=\"1\"/>\n",
            j.limit.0, j.limit.1
        );
        if let Some((m, mult, off)) = &j.mimic {
            s += &format!("    <mimic joint=\"j{m}\" multiplier=\"{mult}\" offset=\"{off}\"/>\n");
        }
        s += "  </joint>\n";
    }
    s += "</robot>\n";
    s
}

/// A TOML description on a generated chain: a trocar on link `link`, optionally a task.
fn chain_toml(tip: usize, link: usize, l_a: &str, h: &str, task: Option<&str>) -> String {
    let mut s = format!(
        "[robot]\nname = \"chain\"\nurdf = \"chain.urdf\"\ntip = \"l{tip}\"\n\n\
         [parameters]\nl_a = {l_a}\n\n[end_effector]\nname = \"tool\"\nxyz = [0, 0, 0.1]\n\n\
         [constraint]\nlink = \"l{link}\"\nxyz = [0, 0, \"l_a\"]\nh = {h}\n"
    );
    if let Some(t) = task {
        s += &format!("\n[task]\nselect = {t}\n");
    }
    s
}

/// A small generated chain (1 to 8 joints), mutated or not, under `jacobian`, or under
/// `generate`, `eval` and `verify` as a TOML description with a trocar constraint.
fn chain_cases() -> BoxedStrategy<Case> {
    let chain = vec(joint_spec(), 1..=8);
    (
        chain,
        edits(xml_edit(Vec::new(), Vec::new()), 4),
        0..10usize,
        any::<usize>(),
        any::<usize>(),
    )
        .prop_flat_map(|(joints, e, tip_pick, link_pick, h_pick)| {
            let n = joints.len();
            let tip = if tip_pick < 7 { n } else { tip_pick % (n + 1) };
            let movable = joints[..tip].iter().filter(|j| j.kind != "fixed").count();
            let urdf = mutate(&chain_urdf(&joints), &e);
            let tips = vec![(format!("l{tip}"), movable)];
            let u1 = urdf.clone();
            let link = at(&link_pick, tip.max(1)) + 1;
            let h = [
                "[\"x\", \"y\"]",
                "[\"x\"]",
                "[\"x\", \"z\"]",
                "[\"x\", \"y\", \"z\"]",
                "[]",
            ][at(&h_pick, 5)];
            let task =
                [None, Some("[\"x\", \"y\", \"z\", \"rz\"]"), Some("[\"x\"]")][at(&h_pick, 3)];
            prop_oneof![
                2 => jacobian_args("chain.urdf".into(), tips).prop_map(move |args| Case {
                    source: "chain",
                    args,
                    files: vec![("chain.urdf".into(), u1.clone())],
                    outputs: Vec::new(),
                }),
                1 => (param_value(), description_command(
                    "robot.toml".into(),
                    movable,
                    vec!["l_a".into()],
                ))
                .prop_map(move |(l_a, (args, outputs, mut files))| {
                    files.push(("chain.urdf".into(), urdf.clone()));
                    files.push((
                        "robot.toml".into(),
                        chain_toml(tip, link, &l_a, h, task).into_bytes(),
                    ));
                    Case {
                        source: "chain",
                        args,
                        files,
                        outputs,
                    }
                }),
            ]
        })
        .boxed()
}

/// A description given by name or shipped path.
fn named() -> BoxedStrategy<Named> {
    let mut v = bases().named.clone();
    for g in [
        "",
        "nope",
        "../x.toml",
        "/",
        ".",
        "-",
        "four-bar.toml",
        "robots/nope.toml",
    ] {
        v.push(Named {
            name: g.to_string(),
            joints: 7,
            params: vec!["l_a".into()],
        });
    }
    select(v).boxed()
}

fn eval_cli() -> BoxedStrategy<Case> {
    named()
        .prop_flat_map(|d| {
            let name = d.name.clone();
            eval_tail(d.joints, &d.params).prop_map(move |t| Case {
                source: "cli",
                args: [vec![arg("eval"), arg(&name)], t].concat(),
                files: Vec::new(),
                outputs: Vec::new(),
            })
        })
        .boxed()
}

fn generate_cli() -> BoxedStrategy<Case> {
    (named(), generate_tail())
        .prop_map(|(d, (a, outputs, files))| Case {
            source: "cli",
            args: [vec![arg("generate"), arg(&d.name)], a].concat(),
            files,
            outputs,
        })
        .boxed()
}

fn verify_cli() -> BoxedStrategy<Case> {
    (named(), verify_tail())
        .prop_map(|(d, a)| Case {
            source: "cli",
            args: [vec![arg("verify"), arg(&d.name)], a].concat(),
            files: Vec::new(),
            outputs: Vec::new(),
        })
        .boxed()
}

fn jacobian_cli() -> BoxedStrategy<Case> {
    let per: Vec<BoxedStrategy<Case>> = bases()
        .urdfs
        .iter()
        .map(|u| {
            jacobian_args(u.path.to_string_lossy().into_owned(), u.tips.clone())
                .prop_map(|args| Case {
                    source: "cli",
                    args,
                    files: Vec::new(),
                    outputs: Vec::new(),
                })
                .boxed()
        })
        .collect();
    prop_oneof![
        8 => proptest::strategy::Union::new(per),
        1 => (select(strs(&["", ".", "/", "nope.urdf", "/dev/null", "sub"])), q_args(7))
            .prop_map(|(u, q)| Case {
                source: "cli",
                args: [args(&["jacobian", "--urdf", &u, "--tip", "panda_link8"]), q].concat(),
                files: vec![("sub/.keep".into(), Vec::new())],
                outputs: Vec::new(),
            }),
    ]
    .boxed()
}

/// `simulate`: mostly the short scenarios, the 200 s scenarios 1 to 4 rarely.
fn simulate_cli() -> BoxedStrategy<Case> {
    let scenario = prop_oneof![
        12 => select(SHORT_SCENARIOS).prop_map(String::from),
        1 => select(strs(&["1", "2", "3", "4"])),
        2 => select(strs(&["5", "", "exp", "0", "-1", "four_bar", "FOUR-BAR"])),
    ];
    let method = choice(&["pinv", "dls", "fi"], &["PINV", "x"]);
    let drift = choice(&["on", "off"], &["x", ""]);
    let speed = select(strs(&[
        "none", "NONE", "2", "0.5", "0", "-1", "1e-320", "1e-9", "1e308", "nan", "inf", "-inf",
        "1e309", "abc", "0.001",
    ]));
    let csv = prop_oneof![
        3 => Just(None),
        2 => Just(Some("trace.csv")),
        1 => select(vec!["sub/trace.csv", "nodir/t.csv", "fig.svg", "sub"]).prop_map(Some),
    ];
    let plot = prop_oneof![
        4 => Just(None),
        2 => Just(Some("fig.svg")),
        1 => Just(Some("fig.png")),
        1 => select(vec!["fig.bmp", "fig", "nodir/f.svg", "trace.csv", "sub/f.SVG"]).prop_map(Some),
    ];
    (
        scenario,
        opt("--method", method, 4),
        opt("--drift-correction", drift, 4),
        opt("--max-joint-speed", speed.boxed(), 3),
        csv,
        plot,
    )
        .prop_map(|(s, m, d, v, csv, plot)| {
            let mut a = [vec![arg("simulate"), arg(s)], m, d, v].concat();
            let mut outputs = Vec::new();
            let valid = [
                "trace.csv",
                "sub/trace.csv",
                "fig.svg",
                "fig.png",
                "sub/f.SVG",
            ];
            for (flag, p) in [("--csv", csv), ("--plot", plot)] {
                if let Some(p) = p {
                    a.push(arg(flag));
                    a.push(arg(p));
                    if valid.contains(&p) && !outputs.contains(&arg(p)) {
                        outputs.push(arg(p));
                    }
                }
            }
            Case {
                source: "cli",
                args: a,
                files: vec![("sub/.keep".into(), Vec::new())],
                outputs,
            }
        })
        .boxed()
}

fn preset_cli() -> BoxedStrategy<Case> {
    let mut names: Vec<String> = bases()
        .named
        .iter()
        .filter(|n| !n.name.contains('/'))
        .map(|n| n.name.clone())
        .collect();
    names.extend(strs(&["", "nope", "UNIDIRECTIONAL", "four-bar", "-"]));
    select(names)
        .prop_map(|n| Case {
            source: "cli",
            args: vec![arg("preset"), arg(n)],
            files: Vec::new(),
            outputs: Vec::new(),
        })
        .boxed()
}

/// Free-form command lines from a pool of subcommands, options and garbage.
fn other_cli() -> BoxedStrategy<Case> {
    vec(select(ARG_TOKENS), 0..7)
        .prop_map(|v| Case {
            source: "cli",
            args: v.into_iter().map(<[u8]>::to_vec).collect(),
            files: Vec::new(),
            outputs: Vec::new(),
        })
        .boxed()
}

// ---------------------------------------------------------------------------------------------
// User trajectories and `[simulation]` sections
// ---------------------------------------------------------------------------------------------

/// The Panda laparoscope's start configuration and its tip there (`trocar eval panda-laparoscope
/// --what fk`); the shaft points down, the trocar 0.15 m above the tip.
const PANDA_Q0: &str =
    "0,-0.7853981633974483,0,-2.356194490192345,0,1.5707963267948966,0.7853981633974483";
const PANDA_TIP: [f64; 3] = [0.3068905665929411, 0.0, 0.19028205230283923];

/// `(lower, upper, speed)` of each joint of a URDF's `<limit>` lines, in order.
fn urdf_joint_limits(path: &Path) -> Vec<(f64, f64, f64)> {
    let text = fs::read_to_string(path).expect("a shipped URDF");
    let attr = |tag: &str, name: &str| -> f64 {
        let key = format!("{name}=\"");
        let start = tag.find(&key).expect("the attribute") + key.len();
        let end = start + tag[start..].find('"').expect("its end");
        tag[start..end].parse().expect("a number")
    };
    text.lines()
        .filter(|l| l.trim_start().starts_with("<limit "))
        .map(|l| (attr(l, "lower"), attr(l, "upper"), attr(l, "velocity")))
        .collect()
}

/// The limits a `simulate` run of the trajectory source must keep, by the robot's joint count.
fn trajectory_limits(joints: usize) -> &'static [(f64, f64, f64)] {
    static PANDA: OnceLock<Vec<(f64, f64, f64)>> = OnceLock::new();
    static UR5: OnceLock<Vec<(f64, f64, f64)>> = OnceLock::new();
    if joints == 7 {
        PANDA.get_or_init(|| urdf_joint_limits(&robots_dir().join("urdf/panda.urdf")))
    } else {
        UR5.get_or_init(|| urdf_joint_limits(&examples_dir().join("robots/urdf/ur5.urdf")))
    }
}

fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// A short path near the Panda's start tip: a hold, a line or a circle, with a roll column, a
/// quaternion, or neither; rows from `t0`.
fn panda_path() -> BoxedStrategy<String> {
    (
        0..3usize,
        0..3usize,
        prop_oneof![Just(0.0), Just(0.02), Just(-0.01)],
        prop_oneof![3 => Just(0.3), 1 => Just(0.05), 1 => Just(1e-6)],
        prop_oneof![3 => Just(0.01), 1 => Just(0.05), 1 => Just(0.3)],
    )
        .prop_map(|(shape, orientation, t0, span, size)| {
            let c = PANDA_TIP;
            let header = ["t,x,y,z,roll", "t,x,y,z,qw,qx,qy,qz", "t,x,y,z"][orientation];
            let mut s = format!("{header}\n");
            for k in 0..=6 {
                let t = t0 + span * k as f64 / 6.0;
                let a = 2.0 * std::f64::consts::PI * k as f64 / 6.0;
                let (dx, dy, dz) = match shape {
                    0 => (0.0, 0.0, 0.0),
                    1 => (size * k as f64 / 6.0, 0.0, -size * k as f64 / 12.0),
                    _ => (size * (a.cos() - 1.0), size * a.sin(), 0.0),
                };
                let tail = match orientation {
                    0 => format!(",{}", 0.1 * a.sin()),
                    // The tip pointing down at q0: the quaternion of R = diag(1, −1, −1) turned
                    // by −π/4 about z.
                    1 => ",0,0.9238795325112867,-0.3826834323650898,0".to_string(),
                    _ => String::new(),
                };
                s += &format!("{t},{},{},{}{tail}\n", c[0] + dx, c[1] + dy, c[2] + dz);
            }
            s
        })
        .boxed()
}

/// CSV edits: numbers, lines, bytes.
fn csv_edit() -> BoxedStrategy<Edit> {
    prop_oneof![
        5 => (any::<usize>(), num()).prop_map(|(i, v)| Edit::Number(i, v)),
        3 => (any::<usize>(), (-1.0f64..1.0).prop_map(|v| format!("{v}")))
            .prop_map(|(i, v)| Edit::Number(i, v)),
        1 => any::<usize>().prop_map(Edit::DeleteLine),
        1 => any::<usize>().prop_map(Edit::DuplicateLine),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Edit::SwapLines(i, j)),
        1 => (any::<usize>(), select(strs(&["t,x,y,z", "# comment", "", "1,2", "t,t,x,y,z", "\u{feff}t,x,y,z,roll"])))
            .prop_map(|(i, s)| Edit::InsertLine(i, s)),
        1 => any::<usize>().prop_map(Edit::Truncate),
        1 => (any::<usize>(), select(BYTES)).prop_map(|(i, b)| Edit::InsertBytes(i, b.to_vec())),
    ]
    .boxed()
}

/// `--trocar` values: the default (none), on the shaft, near it, far off it, garbage.
fn trocar_arg() -> BoxedStrategy<Vec<Vec<u8>>> {
    let c = PANDA_TIP;
    let on = |dx: f64, dz: f64| format!("{},{},{}", c[0] + dx, c[1], c[2] + dz);
    let values = vec![
        on(0.0, 0.15),
        on(5e-4, 0.15),
        on(0.0085, 0.15),
        on(0.2, 0.15),
        on(0.0, 0.3),
        on(0.0, 0.5),
        on(0.0, -0.1),
        "1e300,0,0".to_string(),
        "nan,0,0".to_string(),
        "0,0".to_string(),
    ];
    opt("--trocar", select(values).boxed(), 2)
}

/// `simulate panda-laparoscope --trajectory F` with a generated, mutated path and flags.
fn panda_trajectory_cases() -> BoxedStrategy<Case> {
    let method = choice(&["pinv", "dls", "fi", "qp", "all"], &["x"]);
    let speed = select(strs(&[
        "none", "2", "0.5", "1e-4", "0", "-1", "nan", "inf", "1e308",
    ]));
    let q0 = prop_oneof![
        6 => Just(PANDA_Q0.to_string()),
        // Joint 6 at and beyond its lower limit (-0.0175), joint 4 at its upper one (-0.0698).
        1 => Just("0,-0.7853981633974483,0,-2.356194490192345,0,-0.0175,0.7853981633974483".to_string()),
        1 => Just("0,-0.7853981633974483,0,-2.356194490192345,0,-0.3,0.7853981633974483".to_string()),
        1 => Just("0,-0.7853981633974483,0,-0.0698,0,1.5707963267948966,0.7853981633974483".to_string()),
    ];
    let file = prop_oneof![
        8 => Just(None),
        1 => select(vec!["/dev/zero", "/dev/null", ".", "missing.csv", "/etc/passwd"]).prop_map(Some),
    ];
    (
        panda_path(),
        edits(csv_edit(), 10),
        q0,
        opt("--method", method, 3),
        opt("--max-joint-speed", speed.boxed(), 3),
        opt(
            "--drift-correction",
            select(strs(&["on", "off"])).boxed(),
            5,
        ),
        trocar_arg(),
        file,
    )
        .prop_map(|(path, e, q0, m, v, d, t, file)| {
            let mut args = vec![
                arg("simulate"),
                arg("panda-laparoscope"),
                arg("--trajectory"),
                arg(file.unwrap_or("path.csv")),
                arg("--q0"),
                arg(q0),
            ];
            args.extend([m, v, d, t].concat());
            args.push(arg("--csv"));
            args.push(arg("trace.csv"));
            Case {
                source: "trajectory",
                args,
                files: vec![("path.csv".into(), mutate(&path, &e))],
                outputs: vec![arg("trace.csv")],
            }
        })
        .boxed()
}

/// The UR5 example with a generated `[simulation]` section (gains at and beyond their stable
/// bound at the 2 ms sample time, speed limits, trocars, paths that are devices or not
/// trajectories), now and then mutated as a TOML description is.
fn simulation_section_cases() -> BoxedStrategy<Case> {
    let root = examples_dir();
    let text = fs::read_to_string(root.join("robots/ur5_trocar.toml")).expect("the UR5 example");
    let head = text[..text.find("[simulation]").expect("its section")].to_string();
    let urdf = fs::read(root.join("robots/urdf/ur5.urdf")).expect("its URDF");
    let circle = fs::read_to_string(root.join("trajectories/ur5-circle.csv")).expect("its path");
    // The first second of the circle: 21 rows of 0.05 s after the comments.
    let short: String = circle
        .lines()
        .filter(|l| !l.starts_with('#'))
        .take(22)
        .map(|l| format!("{l}\n"))
        .collect();
    let gain = prop_oneof![
        3 => select(strs(&["5.0", "10.0", "20"])),
        1 => select(strs(&["999", "1000", "1999.9", "2000", "1e6", "-5", "0", "nan", "1e300"])),
    ];
    let entry = |key: &'static str, values: Vec<String>| prop_oneof![2 => Just(String::new()), 3 => select(values).prop_map(move |v| format!("{key} = {v}\n"))];
    (
        (
            entry(
                "trajectory",
                strs(&[
                    "\"path.csv\"",
                    "\"/dev/zero\"",
                    "\"../../etc/passwd\"",
                    "\"urdf/ur5.urdf\"",
                    "\"missing.csv\"",
                ]),
            ),
            entry("method", strs(&["\"dls\"", "\"qp\"", "\"pinv\"", "\"fi\"", "\"all\""])),
            entry(
                "q0",
                strs(&[
                    "[0, -1.5707963267948966, 1.5707963267948966, -1.5707963267948966, -1.5707963267948966, 0]",
                    "[0, -1.5707963267948966, 3.2, -1.5707963267948966, -1.5707963267948966, 0]",
                    "[0, 0]",
                ]),
            ),
            entry(
                "trocar",
                strs(&["[0.4, 0.1, 0.3]", "[1e300, 0, 0]", "[0, 0]", "[\"x\", 0, 0]"]),
            ),
        ),
        (
            gain.clone().prop_map(|v| format!("kp = {v}\n")),
            gain.clone().prop_map(|v| format!("ko = {v}\n")),
            prop_oneof![Just(String::new()), gain.prop_map(|v| format!("kr = {v}\n"))],
            entry("max_joint_speed", strs(&["2", "1e-4", "0", "-1", "nan", "1e6"])),
            entry("null_space_gain", strs(&["10", "0", "999", "1e6", "-1"])),
        ),
        edits(toml_edit(strs(&["l_a", "kp", "trocar"])), 12),
    )
        .prop_map(move |((traj, method, q0, trocar), (kp, ko, kr, speed, gain), e)| {
            let section =
                format!("[simulation]\n{traj}{method}{q0}{trocar}{kp}{ko}{kr}{speed}{gain}");
            let arm = format!("{head}{section}");
            Case {
                source: "trajectory",
                args: vec![arg("simulate"), arg("arm.toml"), arg("--csv"), arg("trace.csv")],
                files: vec![
                    ("arm.toml".into(), mutate(&arm, &e)),
                    ("urdf/ur5.urdf".into(), urdf.clone()),
                    ("path.csv".into(), short.clone().into_bytes()),
                ],
                outputs: vec![arg("trace.csv")],
            }
        })
        .boxed()
}

/// User trajectories and `[simulation]` sections under `simulate`.
fn trajectory_cases() -> BoxedStrategy<Case> {
    prop_oneof![
        3 => panda_trajectory_cases(),
        2 => simulation_section_cases(),
    ]
    .boxed()
}

/// A `simulate` run of the trajectory source that succeeded kept every joint within its URDF
/// range and speed limit on every row of its CSV (the limits are physical: success with a joint
/// past one is a failure).
fn check_limits_kept(case: &Case, dir: &Path) -> Result<(), Problem> {
    let Ok(text) = fs::read_to_string(dir.join("case/trace.csv")) else {
        return Ok(());
    };
    let mut lines = text.lines();
    let Some(header) = lines.next() else {
        return Ok(());
    };
    let columns: Vec<&str> = header.split(',').collect();
    let joints = columns.iter().filter(|c| c.starts_with("qd")).count();
    let limits = trajectory_limits(joints);
    for (row, line) in lines.enumerate() {
        let cells: Vec<f64> = line.split(',').filter_map(|c| c.parse().ok()).collect();
        for (k, &(lo, hi, speed)) in limits.iter().enumerate() {
            let at = |name: String| columns.iter().position(|c| *c == name);
            let (Some(q), Some(qd)) = (at(format!("q{}", k + 1)), at(format!("qd{}", k + 1)))
            else {
                continue;
            };
            let (q, qd) = (cells[q], cells[qd]);
            let tol = 1e-9 * (1.0 + hi.abs());
            if q < lo - tol || q > hi + tol || qd.abs() > speed * (1.0 + 1e-9) {
                return Err(problem(
                    "limit exceeded",
                    format!(
                        "{}: CSV row {}: joint {} at {q} rad, {qd} rad/s (range [{lo}, {hi}], speed {speed}) with exit code 0",
                        case.command_line(),
                        row + 2,
                        k + 1
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Command-line values on the shipped descriptions.
fn cli_cases() -> BoxedStrategy<Case> {
    prop_oneof![
        12 => eval_cli(),
        4 => jacobian_cli(),
        4 => verify_cli(),
        6 => generate_cli(),
        2 => simulate_cli(),
        2 => preset_cli(),
        2 => other_cli(),
    ]
    .boxed()
}

/// Everything, in the long run's proportions.
fn all_cases() -> BoxedStrategy<Case> {
    prop_oneof![
        35 => toml_cases(),
        15 => urdf_cases(),
        15 => chain_cases(),
        32 => cli_cases(),
        6 => trajectory_cases(),
    ]
    .boxed()
}

// ---------------------------------------------------------------------------------------------
// Running a case
// ---------------------------------------------------------------------------------------------

/// How a run ended.
struct Outcome {
    code: Option<i32>,
    signal: Option<i32>,
    timed_out: bool,
    stdout: Vec<u8>,
    stderr: Vec<u8>,
    elapsed: Duration,
    /// The files in the working directory afterwards (relative paths).
    files_after: BTreeSet<Vec<u8>>,
}

impl Outcome {
    /// The exit code, or how the run ended otherwise (for the histograms).
    fn class(&self) -> String {
        if self.timed_out {
            "time-out".into()
        } else if let Some(s) = self.signal {
            format!("signal {s}")
        } else {
            format!("{}", self.code.unwrap_or(-1))
        }
    }
}

fn list_files(dir: &Path, base: &Path, out: &mut BTreeSet<Vec<u8>>) {
    let Ok(rd) = fs::read_dir(dir) else { return };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            list_files(&p, base, out);
        } else {
            out.insert(
                p.strip_prefix(base)
                    .unwrap()
                    .as_os_str()
                    .as_bytes()
                    .to_vec(),
            );
        }
    }
}

/// Writes the case's files into a fresh `dir/case` and runs the binary there, killing it after
/// [`TIMEOUT`].
fn execute(case: &Case, dir: &Path) -> Outcome {
    execute_within(case, dir, TIMEOUT)
}

/// [`execute`] with the time limit `limit`.
fn execute_within(case: &Case, dir: &Path, limit: Duration) -> Outcome {
    let work = dir.join("case");
    let _ = fs::remove_dir_all(&work);
    fs::create_dir_all(&work).unwrap();
    for (name, content) in &case.files {
        let p = work.join(name);
        fs::create_dir_all(p.parent().unwrap()).unwrap();
        fs::write(&p, content).unwrap();
    }
    let out_path = dir.join("stdout");
    let err_path = dir.join("stderr");
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(case.args.iter().map(|a| OsStr::from_bytes(a)))
        .current_dir(&work)
        .stdin(Stdio::null())
        .stdout(fs::File::create(&out_path).unwrap())
        .stderr(fs::File::create(&err_path).unwrap())
        .spawn()
        .expect("the trocar binary runs");
    let mut pause = Duration::from_micros(200);
    let mut timed_out = false;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > limit {
            timed_out = true;
            let _ = child.kill();
            break child.wait().unwrap();
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(Duration::from_millis(10));
    };
    let elapsed = start.elapsed();
    let mut files_after = BTreeSet::new();
    list_files(&work, &work, &mut files_after);
    Outcome {
        code: status.code(),
        signal: if timed_out { None } else { status.signal() },
        timed_out,
        stdout: fs::read(&out_path).unwrap_or_default(),
        stderr: fs::read(&err_path).unwrap_or_default(),
        elapsed,
        files_after,
    }
}

// ---------------------------------------------------------------------------------------------
// Checks
// ---------------------------------------------------------------------------------------------

/// What is wrong with a case's outcome.
#[derive(Clone, Debug)]
struct Problem {
    kind: &'static str,
    detail: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.kind, self.detail)
    }
}

fn problem(kind: &'static str, detail: impl Into<String>) -> Problem {
    Problem {
        kind,
        detail: detail.into(),
    }
}

/// The first word of `text` that reads as a non-finite number (`NaN`, `inf`, `-inf`,
/// `infinity`, `1e999`, …) or is `null`. Words are runs of letters, digits and `._+-`, so
/// `info` or `infinite` in prose are not numbers.
fn non_finite_word(text: &str) -> Option<String> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || "._+-".contains(c)))
        .map(|w| w.trim_end_matches('.'))
        .find(|w| *w == "null" || w.parse::<f64>().is_ok_and(|v| !v.is_finite()))
        .map(str::to_string)
}

fn check_json_value(v: &serde_json::Value) -> Result<(), String> {
    match v {
        serde_json::Value::Null => Err("null in the JSON".into()),
        serde_json::Value::Number(n) if n.as_f64().is_some_and(|x| !x.is_finite()) => {
            Err(format!("non-finite number {n} in the JSON"))
        }
        serde_json::Value::Array(a) => a.iter().try_for_each(check_json_value),
        serde_json::Value::Object(o) => o.values().try_for_each(check_json_value),
        _ => Ok(()),
    }
}

/// A matrix as `eval` / `jacobian` print it: JSON, or rows of finite numbers.
fn check_matrix(text: &str) -> Result<(), Problem> {
    if text.trim_start().starts_with('{') {
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            let v: serde_json::Value = serde_json::from_str(line)
                .map_err(|e| problem("non-finite", format!("JSON does not parse ({e}): {line}")))?;
            check_json_value(&v).map_err(|e| problem("non-finite", e))?;
        }
        return Ok(());
    }
    if text.trim().is_empty() {
        return Err(problem("invalid output", "exit code 0 with no matrix"));
    }
    // Several outputs (`--what a,b`): each after a line `name (catalogue name):`, checked alone.
    let is_title = |l: &str| l.trim_end().ends_with("):") && l.contains(" (");
    if text.lines().any(is_title) {
        let mut block = String::new();
        for line in text.lines() {
            if is_title(line) {
                if !block.trim().is_empty() {
                    check_matrix(&block)?;
                }
                block.clear();
            } else {
                block += line;
                block.push('\n');
            }
        }
        return check_matrix(&block);
    }
    // Labelled text: a header of column labels, then each row's label before its numbers.
    let labelled = text
        .split_whitespace()
        .next()
        .is_some_and(|w| w.parse::<f64>().is_err());
    let lines = text.lines().filter(|l| !l.trim().is_empty());
    for line in lines.skip(usize::from(labelled)) {
        for w in line.split_whitespace().skip(usize::from(labelled)) {
            if !w.parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(problem(
                    "non-finite",
                    format!("matrix entry `{w}` is not a finite number"),
                ));
            }
        }
    }
    Ok(())
}

/// Generated Rust: it parses, and no literal or constant is non-finite.
fn check_rust(code: &str) -> Result<(), Problem> {
    syn::parse_file(code).map_err(|e| {
        problem(
            "invalid output",
            format!("the generated module does not parse: {e}"),
        )
    })?;
    let tokens: proc_macro2::TokenStream = code.parse().map_err(|e| {
        problem(
            "invalid output",
            format!("the generated module does not lex: {e}"),
        )
    })?;
    fn walk(ts: proc_macro2::TokenStream) -> Result<(), String> {
        for tt in ts {
            match tt {
                proc_macro2::TokenTree::Group(g) => walk(g.stream())?,
                proc_macro2::TokenTree::Ident(i) => {
                    let s = i.to_string();
                    // The constants `f64::NAN`, `T::INFINITY`, …; lower-case names are
                    // identifiers taken from the description (a parameter may be `inf`).
                    if ["NAN", "INFINITY", "NEG_INFINITY"].contains(&s.as_str()) {
                        return Err(format!("`{s}` in the generated code"));
                    }
                }
                proc_macro2::TokenTree::Literal(l) => {
                    let s = l.to_string();
                    if s.starts_with(|c: char| c.is_ascii_digit()) {
                        let f32_suffix = s.ends_with("f32");
                        let digits: String = s
                            .trim_end_matches("f32")
                            .trim_end_matches("f64")
                            .chars()
                            .filter(|&c| c != '_')
                            .collect();
                        let finite = if f32_suffix {
                            digits.parse::<f32>().map(f32::is_finite)
                        } else {
                            digits.parse::<f64>().map(f64::is_finite)
                        };
                        if finite == Ok(false) {
                            return Err(format!("non-finite literal `{s}` in the generated code"));
                        }
                    }
                }
                proc_macro2::TokenTree::Punct(_) => {}
            }
        }
        Ok(())
    }
    walk(tokens).map_err(|e| problem("non-finite", e))
}

/// A CSV trace: a header, then rows of finite numbers.
fn check_csv(text: &str) -> Result<(), Problem> {
    let mut rows = text.lines();
    if rows.next().is_none() {
        return Err(problem("invalid output", "empty CSV"));
    }
    for (k, row) in rows.enumerate() {
        for cell in row.split(',') {
            if !cell.trim().parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(problem(
                    "non-finite",
                    format!("CSV row {}: cell `{cell}` is not a finite number", k + 2),
                ));
            }
        }
    }
    Ok(())
}

/// `verify`'s report: the first line names the robot (any name, `nan` included); then every
/// word reads as a finite number or not as a number, and each passed check's error and tolerance
/// are finite numbers.
fn check_verify(text: &str) -> Result<(), Problem> {
    let body: String = text.lines().skip(1).collect::<Vec<_>>().join("\n");
    check_words("the verify report", &body)?;
    for line in body.lines().filter(|l| l.trim_end().ends_with(" ok")) {
        let words: Vec<&str> = line.split_whitespace().collect();
        for w in &words[words.len().saturating_sub(3)..words.len() - 1] {
            if !w.parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(problem(
                    "non-finite",
                    format!("`{w}` in the verify report line `{line}`"),
                ));
            }
        }
    }
    Ok(())
}

fn check_words(what: &str, text: &str) -> Result<(), Problem> {
    match non_finite_word(text) {
        Some(w) => Err(problem("non-finite", format!("`{w}` in {what}"))),
        None => Ok(()),
    }
}

fn check_output_file(name: &[u8], content: &[u8]) -> Result<(), Problem> {
    let shown = String::from_utf8_lossy(name).into_owned();
    let lower = shown.to_ascii_lowercase();
    if lower.ends_with(".png") {
        if !content.starts_with(b"\x89PNG\r\n\x1a\n") {
            return Err(problem("invalid output", format!("{shown} is not a PNG")));
        }
        return Ok(());
    }
    let text = String::from_utf8(content.to_vec())
        .map_err(|_| problem("invalid output", format!("{shown} is not UTF-8")))?;
    if lower.ends_with(".rs") {
        check_rust(&text)
    } else if lower.ends_with(".csv") {
        check_csv(&text)
    } else {
        check_words(&shown, &text)
    }
}

/// Strips one trailing `/` (an output named `out.rs/` is the file `out.rs` when written).
fn normal(p: &[u8]) -> &[u8] {
    p.strip_suffix(b"/").unwrap_or(p)
}

/// The properties every case must have.
fn check(case: &Case, out: &Outcome, dir: &Path) -> Result<(), Problem> {
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.timed_out {
        return Err(problem(
            "hang",
            format!("no exit within {TIMEOUT:?}, then within {RERUN_TIMEOUT:?}"),
        ));
    }
    if let Some(s) = out.signal {
        return Err(problem(
            "signal",
            format!("killed by signal {s}; stderr: {}", tail(&stderr)),
        ));
    }
    if stderr.contains("panicked") {
        return Err(problem("panic", tail(&stderr)));
    }
    // Nothing outside the working directory is touched: `/dev/null` given as an output path was
    // once renamed over, leaving a regular file in its place.
    if !dev_null_is_a_device() {
        return Err(problem(
            "stray file",
            "/dev/null is no longer a character device".to_string(),
        ));
    }
    let code = out.code.unwrap_or(-1);
    if !(0..=2).contains(&code) {
        return Err(problem(
            "exit code",
            format!("exit code {code}; stderr: {}", tail(&stderr)),
        ));
    }
    // No file but the inputs and, after success, the requested outputs.
    let inputs: BTreeSet<&[u8]> = case.files.iter().map(|(n, _)| n.as_bytes()).collect();
    let outputs: BTreeSet<&[u8]> = case.outputs.iter().map(|o| normal(o)).collect();
    for f in &out.files_after {
        let f = f.as_slice();
        if inputs.contains(f) {
            continue;
        }
        if code == 0 && outputs.contains(f) {
            continue;
        }
        return Err(problem(
            "stray file",
            format!(
                "`{}` is left in the working directory after exit code {code}",
                String::from_utf8_lossy(f)
            ),
        ));
    }
    if code != 0 {
        return Ok(());
    }
    let stdout = String::from_utf8(out.stdout.clone())
        .map_err(|_| problem("invalid output", "stdout is not UTF-8"))?;
    if case.asks_help() {
        return check_words("stdout", &stdout);
    }
    match case.command() {
        "eval" | "jacobian" => check_matrix(&stdout)?,
        // Generated Rust: the literals and constants, not the prose of its comments.
        "generate" if !stdout.is_empty() => check_rust(&stdout)?,
        "verify" => check_verify(&stdout)?,
        _ => {}
    }
    if !["generate", "verify"].contains(&case.command()) {
        check_words("stdout", &stdout)?;
    }
    // `simulate`'s summary and `eval`'s notes go to stderr.
    check_words("stderr", &stderr)?;
    if case.source == "trajectory" && case.command() == "simulate" {
        check_limits_kept(case, dir)?;
    }
    for o in &case.outputs {
        let p = dir.join("case").join(OsStr::from_bytes(normal(o)));
        match fs::read(&p) {
            Ok(content) => check_output_file(o, &content)?,
            Err(_) => {
                return Err(problem(
                    "invalid output",
                    format!(
                        "exit code 0 but {} was not written",
                        String::from_utf8_lossy(o)
                    ),
                ))
            }
        }
    }
    Ok(())
}

/// Whether `/dev/null` is still the null device.
fn dev_null_is_a_device() -> bool {
    use std::os::unix::fs::FileTypeExt;
    fs::symlink_metadata("/dev/null").is_ok_and(|m| m.file_type().is_char_device())
}

/// The last lines of a long text.
fn tail(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let from = lines.len().saturating_sub(12);
    let s = lines[from..].join("\n");
    s.chars().take(3000).collect()
}

/// A failure already reported and not yet fixed: recognised by its input and its symptom, counted
/// apart (as `known`), and not failing the run. Remove the entry once the product is fixed: the
/// cases then fail again if it is not.
struct KnownFinding {
    id: &'static str,
    matches: fn(&Case, &Outcome) -> bool,
}

/// The known failures, reported with their reproducers (docs/RELIABILITY.md lists them): none open.
/// F1–F4 (deep expressions, deep URDF nesting, a non-finite numeric `det` and `manip` printed with
/// exit code 0) are fixed, and their reproducers are regression cases.
const KNOWN_FINDINGS: &[KnownFinding] = &[];

/// The known finding `case` fails by, if any (none with `TROCAR_FUZZ_STRICT` set).
fn known(case: &Case, out: &Outcome) -> Option<&'static str> {
    if std::env::var_os("TROCAR_FUZZ_STRICT").is_some() {
        return None;
    }
    KNOWN_FINDINGS
        .iter()
        .find(|k| (k.matches)(case, out))
        .map(|k| k.id)
}

/// Runs a case, once more when it timed out (a loaded machine), and checks it; a failure that
/// is a known finding is counted apart and passes.
fn run_case(case: &Case, dir: &Path, stats: &Mutex<Stats>) -> (Outcome, Result<(), Problem>) {
    let mut out = execute(case, dir);
    if out.timed_out {
        stats.lock().unwrap().reruns += 1;
        out = execute_within(case, dir, RERUN_TIMEOUT);
    }
    let mut result = check(case, &out, dir);
    if result.is_err() {
        if let Some(id) = known(case, &out) {
            *stats.lock().unwrap().known.entry(id).or_default() += 1;
            result = Ok(());
        }
    }
    if std::env::var_os("TROCAR_FUZZ_VERBOSE").is_some() {
        let err = String::from_utf8_lossy(&out.stderr);
        let first: String = err.lines().next().unwrap_or("").chars().take(160).collect();
        let line: String = case.command_line().chars().take(160).collect();
        eprintln!("[{}] {} {line}\n      {first}", case.source, out.class());
    }
    stats
        .lock()
        .unwrap()
        .record(case, &out, result.as_ref().err());
    (out, result)
}

// ---------------------------------------------------------------------------------------------
// Statistics and reproducers
// ---------------------------------------------------------------------------------------------

#[derive(Default)]
struct Stats {
    cases: u64,
    /// command → exit class → count.
    by_command: BTreeMap<&'static str, BTreeMap<String, u64>>,
    by_source: BTreeMap<&'static str, u64>,
    exit: BTreeMap<String, u64>,
    /// problem kind → count.
    problems: BTreeMap<&'static str, u64>,
    reruns: u64,
    /// known finding → cases that failed by it.
    known: BTreeMap<&'static str, u64>,
    busy: Duration,
    slowest: (Duration, String),
}

impl Stats {
    fn record(&mut self, case: &Case, out: &Outcome, problem: Option<&Problem>) {
        self.cases += 1;
        *self
            .by_command
            .entry(case.command())
            .or_default()
            .entry(out.class())
            .or_default() += 1;
        *self.by_source.entry(case.source).or_default() += 1;
        *self.exit.entry(out.class()).or_default() += 1;
        if let Some(p) = problem {
            *self.problems.entry(p.kind).or_default() += 1;
        }
        self.busy += out.elapsed;
        if out.elapsed > self.slowest.0 {
            self.slowest = (out.elapsed, case.command_line());
        }
    }

    fn count(&self, kind: &str) -> u64 {
        self.problems.get(kind).copied().unwrap_or(0)
    }

    fn summary(&self, label: &str, wall: Duration, workers: usize, seed: u64) -> String {
        let hist = |m: &BTreeMap<String, u64>| {
            m.iter()
                .map(|(k, v)| format!("{k}: {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut s = format!(
            "fuzz {label}: {} cases in {:.1} s ({workers} worker{}, seed {seed}, binary {})\n",
            self.cases,
            wall.as_secs_f64(),
            if workers == 1 { "" } else { "s" },
            env!("CARGO_BIN_EXE_trocar"),
        );
        s += "  per command (exit code: cases):\n";
        for (c, m) in &self.by_command {
            let n: u64 = m.values().sum();
            s += &format!("    {c:<9} {n:>7}  ({})\n", hist(m));
        }
        s += &format!(
            "  per source: {}\n",
            self.by_source
                .iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        s += &format!("  exit codes: {}\n", hist(&self.exit));
        s += &format!(
            "  panics {}, aborts/signals {}, other exit codes {}, hangs (> 10 s, then > 60 s) {}, \
             non-finite exit-0 outputs {}, invalid outputs {}, stray files {}\n",
            self.count("panic"),
            self.count("signal"),
            self.count("exit code"),
            self.count("hang"),
            self.count("non-finite"),
            self.count("invalid output"),
            self.count("stray file"),
        );
        if !self.known.is_empty() {
            s += &format!(
                "  known findings (not counted above): {}\n",
                self.known
                    .iter()
                    .map(|(k, v)| format!("{k}: {v}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        s += &format!(
            "  mean case {:.1} ms, slowest {:.2} s ({}), re-runs after a time-out {}\n",
            self.busy.as_secs_f64() * 1e3 / self.cases.max(1) as f64,
            self.slowest.0.as_secs_f64(),
            self.slowest.1.chars().take(200).collect::<String>(),
            self.reruns,
        );
        s
    }
}

fn failures_dir() -> PathBuf {
    std::env::var_os("TROCAR_FUZZ_FAILURES")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-failures"))
}

/// Saves a failing case: its input files, `cmd.sh` (run it in that directory) and
/// `report.txt`. Returns the directory.
fn save_reproducer(label: &str, case: &Case, out: &Outcome, p: &Problem) -> PathBuf {
    static SEQ: AtomicUsize = AtomicUsize::new(0);
    let k = SEQ.fetch_add(1, Ordering::Relaxed);
    let kind = p.kind.replace(' ', "-");
    let dir = failures_dir().join(format!(
        "{label}-{}-{k:04}-{}-{kind}",
        std::process::id(),
        case.command()
    ));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    for (name, content) in &case.files {
        let f = dir.join(name);
        fs::create_dir_all(f.parent().unwrap()).unwrap();
        fs::write(f, content).unwrap();
    }
    let script = format!(
        "#!/usr/bin/env bash\n# Run in this directory; TROCAR names the binary.\n\"${{TROCAR:-trocar}}\"{}\n",
        case.command_line().trim_start_matches("trocar")
    );
    fs::write(dir.join("cmd.sh"), script).unwrap();
    let report = format!(
        "{p}\n\ncommand: {}\nexit: {} after {:.3} s\n\n--- stderr\n{}\n--- stdout (start)\n{}\n",
        case.command_line(),
        out.class(),
        out.elapsed.as_secs_f64(),
        String::from_utf8_lossy(&out.stderr)
            .chars()
            .take(20_000)
            .collect::<String>(),
        String::from_utf8_lossy(&out.stdout)
            .chars()
            .take(5_000)
            .collect::<String>(),
    );
    fs::write(dir.join("report.txt"), report).unwrap();
    dir
}

// ---------------------------------------------------------------------------------------------
// Campaigns
// ---------------------------------------------------------------------------------------------

fn env_number(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(default)
}

fn rng(seed: u64, worker: u64) -> TestRng {
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    bytes[8..16].copy_from_slice(&worker.to_le_bytes());
    bytes[16..].copy_from_slice(b"trocar-fuzz-0001");
    TestRng::from_seed(RngAlgorithm::ChaCha, &bytes)
}

fn config(cases: u32) -> Config {
    Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 200,
        max_shrink_time: 60_000,
        ..Config::default()
    }
}

fn scratch(label: &str, worker: usize) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("fuzz")
        .join(format!("{label}-{}-w{worker}", std::process::id()));
    fs::create_dir_all(&d).unwrap();
    d
}

/// A bounded run (CI): one worker; the first failing case is shrunk by proptest, saved and
/// reported.
fn bounded(label: &str, strategy: BoxedStrategy<Case>, default_cases: u32) {
    let cases = env_number("TROCAR_FUZZ_CI_CASES", default_cases.into()) as u32;
    let seed = env_number("TROCAR_FUZZ_SEED", 1);
    let dir = scratch(label, 0);
    let stats = Mutex::new(Stats::default());
    let start = Instant::now();
    let mut runner = TestRunner::new_with_rng(config(cases), rng(seed, 0));
    let result = runner.run(&strategy, |case| {
        let (_, r) = run_case(&case, &dir, &stats);
        r.map_err(|p| TestCaseError::fail(p.to_string()))
    });
    let stats = stats.into_inner().unwrap();
    eprintln!("{}", stats.summary(label, start.elapsed(), 1, seed));
    let _ = fs::remove_dir_all(&dir);
    match result {
        Ok(()) => {}
        Err(TestError::Fail(reason, case)) => {
            let scratch_dir = scratch(label, 9);
            let out = execute(&case, &scratch_dir);
            let p = check(&case, &out, &scratch_dir)
                .err()
                .unwrap_or_else(|| problem("flaky", reason.to_string()));
            let saved = save_reproducer(label, &case, &out, &p);
            panic!(
                "{label}: {reason}\nminimal case (saved in {}):\n{case:?}",
                saved.display()
            );
        }
        Err(e) => panic!("{label}: {e}"),
    }
}

/// The long run: `cases` cases over at most two workers; every failure is recorded and saved,
/// and the run fails at the end when there was any.
fn long_run(
    label: &str,
    strategy: fn() -> BoxedStrategy<Case>,
    cases: u64,
    workers: usize,
    seed: u64,
) {
    let stats = Mutex::new(Stats::default());
    let failures: Mutex<Vec<(String, Problem, PathBuf)>> = Mutex::new(Vec::new());
    let done = AtomicUsize::new(0);
    let start = Instant::now();
    std::thread::scope(|s| {
        for w in 0..workers {
            let share = cases / workers as u64 + u64::from((w as u64) < cases % workers as u64);
            let (stats, failures, done) = (&stats, &failures, &done);
            s.spawn(move || {
                let strategy = strategy();
                let dir = scratch(label, w);
                let mut runner =
                    TestRunner::new_with_rng(config(share as u32), rng(seed, w as u64));
                let _ = runner.run(&strategy, |case| {
                    let (out, r) = run_case(&case, &dir, stats);
                    if let Err(p) = r {
                        let mut f = failures.lock().unwrap();
                        let saved = if f.len() < 500 {
                            save_reproducer(label, &case, &out, &p)
                        } else {
                            PathBuf::new()
                        };
                        f.push((case.command_line(), p, saved));
                    }
                    let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                    if n % 5000 == 0 {
                        eprintln!(
                            "fuzz {label}: {n} cases, {:.0} s, {} failures",
                            start.elapsed().as_secs_f64(),
                            failures.lock().unwrap().len()
                        );
                    }
                    Ok(())
                });
                let _ = fs::remove_dir_all(&dir);
            });
        }
    });
    let stats = stats.into_inner().unwrap();
    let failures = failures.into_inner().unwrap();
    let summary = stats.summary(label, start.elapsed(), workers, seed);
    eprintln!("{summary}");
    if !failures.is_empty() {
        let mut groups: BTreeMap<String, usize> = BTreeMap::new();
        for (_, p, _) in &failures {
            let first = p
                .detail
                .lines()
                .find(|l| l.contains("panicked"))
                .unwrap_or(p.detail.lines().next().unwrap_or(""));
            *groups
                .entry(format!(
                    "{}: {}",
                    p.kind,
                    first.chars().take(160).collect::<String>()
                ))
                .or_default() += 1;
        }
        let mut msg = format!(
            "{} failing cases (reproducers in {}):\n",
            failures.len(),
            failures_dir().display()
        );
        for (g, n) in &groups {
            msg += &format!("  {n:>6} × {g}\n");
        }
        for (cmd, p, saved) in failures.iter().take(30) {
            msg += &format!("- {cmd}\n    {p}\n    saved: {}\n", saved.display());
        }
        panic!("{msg}");
    }
}

// ---------------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------------

/// Shipped TOML descriptions (serial robots, closed mechanisms, and the URDFs they read)
/// mutated, under `generate`, `eval` and `verify`.
#[test]
fn mutated_toml_descriptions_fail_cleanly() {
    bounded("toml", toml_cases(), 300);
}

/// Shipped URDFs mutated and small generated chains (cycles, unknown links, mimics, extreme
/// origins and axes), under `jacobian`, or as the chain of a TOML description.
#[test]
fn mutated_urdf_descriptions_fail_cleanly() {
    bounded(
        "urdf",
        prop_oneof![urdf_cases(), chain_cases()].boxed(),
        300,
    );
}

/// Command-line values on the shipped descriptions: `--q` lists, `--param`, `--what`,
/// `--samples`, `--real`, output paths, `simulate` options, `preset` names, free-form argv.
#[test]
fn command_line_values_fail_cleanly() {
    bounded("cli", cli_cases(), 400);
}

/// User trajectories (generated paths near the Panda's tip, mutated; `--trocar`, `--q0`,
/// `--method`, `--max-joint-speed` values) and the UR5 example's `[simulation]` section
/// (gains at and past their stable bound, speed limits, trocars, device and foreign paths),
/// under `simulate`: besides the checks of every case, a run that succeeds kept every joint
/// within its URDF range and speed limit.
#[test]
fn user_trajectories_and_simulation_sections_fail_cleanly() {
    bounded("trajectory", trajectory_cases(), 120);
}

/// The long run: `TROCAR_FUZZ_CASES` (default 100000) cases of every kind over
/// `TROCAR_FUZZ_WORKERS` (default 2, at most 2) threads; prints the figures of docs/RELIABILITY.md.
#[test]
#[ignore = "long: about 10^5 cases; run with --ignored --nocapture"]
fn long_fuzz_run() {
    let cases = env_number("TROCAR_FUZZ_CASES", 100_000);
    let workers = env_number("TROCAR_FUZZ_WORKERS", 2).clamp(1, 2) as usize;
    let seed = env_number("TROCAR_FUZZ_SEED", 1);
    long_run("long", all_cases, cases, workers, seed);
}

/// The minimal reproducers of the fuzzing's findings: each passes the checks (fixed), or fails in
/// the way an entry of [`KNOWN_FINDINGS`] recognises (not fixed yet). The first two (an
/// expression 12000 parentheses deep, URDF elements nested 14000 deep) overflowed the stack.
#[test]
fn fuzz_findings_stay_fixed_or_known() {
    let deep = "(".repeat(12_000) + "l_8" + &")".repeat(12_000);
    let robot = fs::read_to_string(robots_dir().join("bidirectional-zy.toml"))
        .unwrap()
        .replace(
            "xyz = [0, \"l_8\", 0]",
            &format!("xyz = [0, \"{deep}\", 0]"),
        );
    assert!(robot.contains(&deep));
    let nested = format!(
        "<robot name=\"r\">{}{}<link name=\"a\"/></robot>\n",
        "<a>".repeat(14_000),
        "</a>".repeat(14_000)
    );
    let case = |a: &[&str], files: Vec<(&str, String)>| Case {
        source: "cli",
        args: args(a),
        files: files
            .into_iter()
            .map(|(n, c)| (n.to_string(), c.into_bytes()))
            .collect(),
        outputs: Vec::new(),
    };
    let cases = [
        case(
            &["eval", "robot.toml", "--q=0,0,0,0,0,0,0,0"],
            vec![("robot.toml", robot)],
        ),
        case(
            &["jacobian", "--urdf", "nested.urdf", "--tip", "a", "--q=0"],
            vec![("nested.urdf", nested)],
        ),
        case(
            &[
                "eval",
                "planar-stewart",
                "--q=0,0,0,0,0,0,0,0,0",
                "--what",
                "det",
                "--numeric",
            ],
            Vec::new(),
        ),
        case(
            &[
                "eval",
                "dia10_like_zy",
                "--q=0,-0.3,0.9,0.2,-0.6,0.1,0.5,0.3",
                "--param",
                "l_a=1e-200",
                "--what",
                "manip",
                "--numeric",
                "--json",
            ],
            Vec::new(),
        ),
    ];
    let dir = scratch("known", 0);
    for case in &cases {
        let out = execute(case, &dir);
        match check(case, &out, &dir) {
            Ok(()) => eprintln!("fixed: {}", case.command_line()),
            Err(p) => match known(case, &out) {
                Some(id) => eprintln!("still failing ({id}): {}", case.command_line()),
                None => panic!("{p}\nnot a known finding: {}", case.command_line()),
            },
        }
    }
    let _ = fs::remove_dir_all(&dir);
}

/// The checks themselves: prose is not a number, non-finite numbers are found wherever they are.
#[test]
fn the_checks_find_non_finite_numbers() {
    assert_eq!(non_finite_word("info: infinite null-space, 1e-3"), None);
    assert_eq!(non_finite_word("max error NaN"), Some("NaN".into()));
    assert_eq!(non_finite_word("w = -inf."), Some("-inf".into()));
    assert_eq!(non_finite_word("1e999"), Some("1e999".into()));
    assert!(check_matrix("  0.1  -0.2\n  3.0  4e-300").is_ok());
    assert!(check_matrix("  0.1  NaN").is_err());
    assert!(check_matrix(r#"{"rows": 1, "cols": 2, "data": [[1.0, null]]}"#).is_err());
    assert!(check_matrix(r#"{"rows": 1, "cols": 1, "data": [[1.0]]}"#).is_ok());
    assert!(check_rust("/// NaN and inf in a comment\nfn f() -> f64 { 1.5e3_f64 }").is_ok());
    assert!(check_rust("fn f() -> f64 { f64::NAN }").is_err());
    assert!(check_rust("struct P { inf: f64, nan: f64 }").is_ok());
    assert!(check_verify("nan: 4 random samples\nfk: generated   1.0e-16  1e-12  ok").is_ok());
    assert!(check_verify("r: 4 random samples\nfk: generated   NaN  1e-12  ok").is_err());
    assert!(check_rust("fn f() -> f32 { 1e308_f32 }").is_err());
    assert!(check_rust("fn f() -> f64 { 1e400 }").is_err());
    assert!(check_csv("t,x\n0,1\n0.1,2e-3").is_ok());
    assert!(check_csv("t,x\n0,1\n0.1,inf").is_err());
    let mut t = b"[parameters]\nl_a = 0.15\nname = \"panda_link8\"\n".to_vec();
    apply(&mut t, &Edit::Number(0, "1e308".into()));
    assert_eq!(t, b"[parameters]\nl_a = 1e308\nname = \"panda_link8\"\n");
    apply(&mut t, &Edit::SwapKeys(0, usize::MAX));
    assert_eq!(t, b"[parameters]\nname = 1e308\nl_a = \"panda_link8\"\n");
}

// ---------------------------------------------------------------------------------------------
// The output layer
// ---------------------------------------------------------------------------------------------

/// What is at an output's path before the command runs.
#[derive(Clone, Copy, Debug)]
enum Slot {
    /// Nothing.
    Absent,
    /// A regular file, mode 0600.
    Existing,
    /// A symbolic link to an existing file (`old.txt`).
    LinkToFile,
    /// A dangling symbolic link to `t.out` (the same name for both outputs).
    Dangling,
    /// A dangling symbolic link into a missing directory.
    DanglingIntoNowhere,
    /// A symbolic link to a directory.
    LinkToDir,
    /// A directory.
    Directory,
    /// A symbolic link to itself.
    Loop,
    /// A name in a directory that does not exist.
    MissingDir,
    /// A name in `/proc`, where no file can be created.
    Proc,
    /// A symbolic link to the description the command reads.
    LinkToInput,
    /// The description itself.
    Input,
    /// A name of about 250 bytes (some too long).
    Long(usize),
}

fn slot() -> BoxedStrategy<Slot> {
    prop_oneof![
        3 => Just(Slot::Absent),
        2 => Just(Slot::Existing),
        2 => Just(Slot::LinkToFile),
        2 => Just(Slot::Dangling),
        1 => Just(Slot::DanglingIntoNowhere),
        1 => Just(Slot::LinkToDir),
        1 => Just(Slot::Directory),
        1 => Just(Slot::Loop),
        1 => Just(Slot::MissingDir),
        1 => Just(Slot::Proc),
        1 => Just(Slot::LinkToInput),
        1 => Just(Slot::Input),
        1 => (240usize..262).prop_map(Slot::Long),
    ]
    .boxed()
}

/// Lays out `slot` for an output named `name` (with its extension) in `dir`; returns the path
/// to give the command.
fn lay_out(dir: &Path, slot: Slot, name: &str) -> String {
    use std::os::unix::fs::{symlink, PermissionsExt};
    let p = dir.join(name);
    match slot {
        Slot::Absent => name.into(),
        Slot::Existing => {
            fs::write(&p, "existing").unwrap();
            fs::set_permissions(&p, fs::Permissions::from_mode(0o600)).unwrap();
            name.into()
        }
        Slot::LinkToFile => {
            symlink("old.txt", &p).unwrap();
            name.into()
        }
        Slot::Dangling => {
            symlink("t.out", &p).unwrap();
            name.into()
        }
        Slot::DanglingIntoNowhere => {
            symlink("nowhere/t.out", &p).unwrap();
            name.into()
        }
        Slot::LinkToDir => {
            symlink("sub", &p).unwrap();
            name.into()
        }
        Slot::Directory => {
            fs::create_dir(&p).unwrap();
            name.into()
        }
        Slot::Loop => {
            symlink(name, &p).unwrap();
            name.into()
        }
        Slot::MissingDir => format!("nowhere/{name}"),
        Slot::Proc => format!("/proc/{name}"),
        Slot::LinkToInput => {
            symlink("in.toml", &p).unwrap();
            name.into()
        }
        Slot::Input => "in.toml".into(),
        Slot::Long(n) => {
            let ext = Path::new(name).extension().unwrap().to_str().unwrap();
            format!("{}.{ext}", "x".repeat(n.saturating_sub(ext.len() + 1)))
        }
    }
}

/// Every entry under `dir`: its path, and its kind with the link target or the content and
/// mode.
fn tree(dir: &Path) -> BTreeMap<PathBuf, String> {
    use std::os::unix::fs::PermissionsExt;
    let mut out = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let m = fs::symlink_metadata(&p).unwrap();
            let what = if m.file_type().is_symlink() {
                format!("link {:?}", fs::read_link(&p).unwrap())
            } else if m.is_dir() {
                todo.push(p.clone());
                "dir".into()
            } else {
                let bytes = fs::read(&p).unwrap();
                format!(
                    "file {:o} {} {:x}",
                    m.permissions().mode() & 0o7777,
                    bytes.len(),
                    bytes.iter().fold(0u64, |h, b| h
                        .wrapping_mul(1_099_511_628_211)
                        .wrapping_add(u64::from(*b)))
                )
            };
            out.insert(p.strip_prefix(dir).unwrap().to_path_buf(), what);
        }
    }
    out
}

/// The output layer: outputs that exist, are links (to files, dangling, to a directory, to the
/// input, in a loop), directories, in missing or unwritable directories, too long, or the input
/// itself, for `generate -o` and for `simulate --csv --plot`. Each case must end with exit code
/// 0, 1 or 2 and no panic; after a failure the directory is exactly as before (no output, no
/// temporary, the input untouched); after success only the outputs' files changed, each a
/// regular file with content, a replaced one with its mode, and no temporary is left.
#[test]
fn fuzz_output_layer() {
    let cases = env_number("TROCAR_FUZZ_OUTPUT_CASES", 60) as u32;
    let seed = env_number("TROCAR_FUZZ_SEED", 1);
    let root = scratch("outputs", 0);
    let unidirectional = fs::read(robots_dir().join("unidirectional.toml")).unwrap();
    let counter = AtomicUsize::new(0);
    let strategy = (
        any::<bool>(),
        slot(),
        slot(),
        select(vec!["svg", "png", "txt"]),
    );
    let mut runner = TestRunner::new_with_rng(config(cases), rng(seed, 7));
    let result = runner.run(&strategy, |(generate, a, b, ext)| {
        let dir = root.join(format!("case{}", counter.fetch_add(1, Ordering::Relaxed)));
        fs::create_dir_all(dir.join("sub")).unwrap();
        fs::write(dir.join("in.toml"), &unidirectional).unwrap();
        fs::write(dir.join("old.txt"), "old").unwrap();
        let a_path = lay_out(&dir, a, if generate { "m.rs" } else { "t.csv" });
        let plot_name = format!("f.{ext}");
        let b_path = lay_out(&dir, b, &plot_name);
        let args: Vec<&str> = if generate {
            vec!["generate", "in.toml", "-o", &a_path]
        } else {
            vec!["simulate", "four-bar", "--csv", &a_path, "--plot", &b_path]
        };
        let before = tree(&dir);
        let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let after = tree(&dir);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let code = out.status.code();
        prop_assert!(
            matches!(code, Some(0..=2)) && !stderr.contains("panicked"),
            "{args:?}: {:?} {stderr}",
            out.status
        );
        // `generate` reads the description: it is never replaced (`simulate` reads no file).
        prop_assert!(
            !generate || fs::read(dir.join("in.toml")).unwrap() == unidirectional,
            "{:?}: the input changed",
            args
        );
        if code == Some(0) {
            let outputs: Vec<&str> = if generate {
                vec![&a_path]
            } else {
                vec![&a_path, &b_path]
            };
            let mut targets = BTreeSet::new();
            for o in &outputs {
                let target = fs::canonicalize(dir.join(o)).unwrap();
                let m = fs::metadata(&target).unwrap();
                prop_assert!(m.is_file() && m.len() > 0, "{args:?}: {o} is not written");
                if let Ok(rel) = target.strip_prefix(fs::canonicalize(&dir).unwrap()) {
                    targets.insert(rel.to_path_buf());
                }
            }
            for (p, what) in &after {
                if targets.contains(p) {
                    if let Some(old) = before.get(p) {
                        // A replaced file keeps its mode.
                        prop_assert_eq!(
                            old.split(' ').nth(1),
                            what.split(' ').nth(1),
                            "{:?}: the mode of {:?} changed",
                            &args,
                            p
                        );
                    }
                    continue;
                }
                prop_assert_eq!(
                    before.get(p),
                    Some(what),
                    "{:?}: {:?} appeared or changed",
                    &args,
                    p
                );
            }
        } else {
            prop_assert_eq!(
                &before,
                &after,
                "{:?} failed ({}) and changed the directory",
                &args,
                stderr
            );
        }
        let _ = fs::remove_dir_all(&dir);
        Ok(())
    });
    let _ = fs::remove_dir_all(&root);
    if let Err(e) = result {
        panic!("output layer: {e}");
    }
}
