//! Garbage never panics: random text, and preset files and the URDF fixture mutated at random,
//! give `Ok` or `Err`, and every error has a field and a message.

use proptest::prelude::*;
use trocar_model::description::{preset, preset_names, RobotDescription};

const ARM7_URDF: &str = include_str!("data/arm7.urdf");

fn check_toml(text: &str) {
    match RobotDescription::from_toml_str(text, None) {
        Ok(d) => {
            // Accepted descriptions are valid, and serialise to text that reads back.
            assert!(d.problems().is_empty());
            RobotDescription::from_toml_str(&d.to_toml_string(), None).unwrap();
        }
        Err(e) => {
            assert!(!e.field.is_empty() && !e.message.is_empty(), "{e:?}");
            let _ = e.to_string();
        }
    }
    if let Ok(d) = RobotDescription::from_toml_str_unvalidated(text, None) {
        let _ = d.problems();
        let _ = d.to_toml_string();
    }
}

fn check_urdf(text: &str, tip: &str) {
    if let Err(e) = RobotDescription::from_urdf_str(text, tip) {
        assert!(!e.field.is_empty() && !e.message.is_empty(), "{e:?}");
        // A document the URDF reader refuses is located in the file.
        if e.field == "(document)" {
            assert!(e.line.is_some() && e.column.is_some(), "{e:?}");
        }
    }
}

/// One edit of `text`: delete, insert or replace a span, or duplicate a line.
#[derive(Clone, Debug)]
enum Edit {
    Delete(usize, usize),
    Insert(usize, String),
    Replace(usize, String),
    DuplicateLine(usize),
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for edit in edits {
        let n = chars.len().max(1);
        match edit {
            Edit::Delete(at, len) => {
                let at = at % n;
                let end = (at + len).min(chars.len());
                if at < end {
                    chars.drain(at..end);
                }
            }
            Edit::Insert(at, s) => {
                let at = (at % n).min(chars.len());
                chars.splice(at..at, s.chars());
            }
            Edit::Replace(at, s) => {
                let at = at % n;
                let end = (at + s.chars().count()).min(chars.len());
                chars.splice(at.min(end)..end, s.chars());
            }
            Edit::DuplicateLine(k) => {
                let text: String = chars.iter().collect();
                let lines: Vec<&str> = text.split('\n').collect();
                let k = k % lines.len();
                let mut out = lines.clone();
                out.insert(k, lines[k]);
                chars = out.join("\n").chars().collect();
            }
        }
    }
    chars.into_iter().collect()
}

/// Fragments that are likely to matter: keys, numbers at the edges, TOML and XML syntax.
fn fragment() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e999".to_string()),
        Just("0".to_string()),
        Just("-1".to_string()),
        Just("18446744073709551616".to_string()),
        Just("\"l_q\"".to_string()),
        Just("\"l_a*l_b\"".to_string()),
        Just("[]".to_string()),
        Just("[[joints]]\n".to_string()),
        Just("[constraint]\n".to_string()),
        Just("h = [[1,2,3]]\n".to_string()),
        Just("link = 99\n".to_string()),
        Just("wrist = \"zx\"\n".to_string()),
        Just("type = \"twist\"\n".to_string()),
        Just("é∑😀".to_string()),
        Just("\"".to_string()),
        Just("<".to_string()),
        Just("/>".to_string()),
        Just("type=\"floating\"".to_string()),
        Just("xyz=\"nan 0 0\"".to_string()),
        "[ -~\n]{0,12}",
        any::<String>(),
    ]
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), 1..20usize).prop_map(|(a, l)| Edit::Delete(a, l)),
        (any::<usize>(), fragment()).prop_map(|(a, s)| Edit::Insert(a, s)),
        (any::<usize>(), fragment()).prop_map(|(a, s)| Edit::Replace(a, s)),
        any::<usize>().prop_map(Edit::DuplicateLine),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn random_text_never_panics(text in any::<String>()) {
        check_toml(&text);
        check_urdf(&text, "tool");
    }

    #[test]
    fn random_toml_like_text_never_panics(text in "([a-z_\\[\\]=\", .0-9\n-]|nan|inf|joints|constraint|robot){0,200}") {
        check_toml(&text);
    }

    #[test]
    fn mutated_presets_never_panic(
        which in 0..5usize,
        edits in proptest::collection::vec(edit(), 1..6),
    ) {
        let name = preset_names().nth(which).unwrap();
        check_toml(&apply(preset(name).unwrap(), &edits));
    }

    #[test]
    fn mutated_urdf_never_panics(
        edits in proptest::collection::vec(edit(), 1..6),
        tip in prop_oneof![Just("tool"), Just("link4"), Just("camera"), Just("nowhere"), Just("")],
    ) {
        check_urdf(&apply(ARM7_URDF, &edits), tip);
    }
}
