//! Reading scene JSON strictly, with errors that name the object and field.
//!
//! serde's derived structs also accept the *sequence form* (`"settings": [0.05]` is read as
//! `element_size`, a whole scene as nested positional arrays): a typo'd bracket would then
//! bake something the user never wrote. So the text is first read as a `Value`, every place
//! the format says "object" is checked to hold an object, and only then are the serde types
//! filled from it.
//!
//! Errors carry the path of the bad value (`meshes[1].albedo[3]`) instead of serde_json's
//! line and column, which mean nothing to someone who exported the file from Blender. The
//! path is tracked by `serde_path_to_error` (it wraps the deserializer and records each map
//! key and sequence index on the way down), rather than by hand-written deserializers for
//! every type, which would duplicate the format in two places.

use std::fmt;

use serde::de::{self, DeserializeOwned, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use serde_json::Value;

use super::json::{LightJson, PerPolygon, SceneJson, SettingsJson, SCENE_FORMAT, SCENE_VERSION};
use crate::BakeError;

/// One step of a path into the scene JSON.
#[derive(Debug, Clone, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// Parses scene JSON text: objects only where the format has objects, errors located by path.
pub fn scene_from_str(text: &str) -> Result<SceneJson, BakeError> {
    let mut de = serde_json::Deserializer::from_str(text);
    let value: Value = match serde_path_to_error::deserialize(&mut de) {
        Ok(v) => v,
        // A syntax error has no field to name yet: keep serde_json's line and column, and
        // put the path of the value being read in front (`meshes[0].positions[2][1]`).
        Err(e) => {
            let segs = segs(e.path());
            let msg = e.into_inner().to_string();
            return Err(if segs.is_empty() {
                BakeError::Format(msg)
            } else {
                BakeError::Format(format!("{}: {msg}", show(&segs)))
            });
        }
    };
    de.end()
        .map_err(|e| BakeError::Format(format!("after the scene: {e}")))?;
    objects_only(&value, &Shape::Scene, &mut Vec::new(), &value)?;
    fill(&value, &[], &value)
}

/// A light given as a JSON value (the Python binding's dict), `index` its place in `lights`.
pub fn light_from_value(v: &Value, index: usize) -> Result<LightJson, BakeError> {
    let root = serde_json::json!({ "lights": vec![Value::Null; index].into_iter().chain([v.clone()]).collect::<Vec<_>>() });
    let mut at = vec![Seg::Key("lights".into()), Seg::Index(index)];
    objects_only(v, &Shape::Light, &mut at, &root)?;
    fill(v, &at, &root)
}

/// The `settings` object given as a JSON value (the Python binding's dict).
pub fn settings_from_value(v: &Value) -> Result<SettingsJson, BakeError> {
    let mut at = vec![Seg::Key("settings".into())];
    objects_only(v, &Shape::Object, &mut at, v)?;
    fill(v, &at, v)
}

/// Fills `T` from `v` (found at `prefix` in `root`), turning serde's error into ours.
fn fill<T: DeserializeOwned>(v: &Value, prefix: &[Seg], root: &Value) -> Result<T, BakeError> {
    serde_path_to_error::deserialize(v).map_err(|e| {
        let mut at = prefix.to_vec();
        at.extend(segs(e.path()));
        located(&at, root, &e.into_inner().to_string())
    })
}

/// What the format has at a place: where an object is required, and what lies inside.
enum Shape {
    Scene,
    Mesh,
    Light,
    /// An object whose fields are all plain values.
    Object,
}

fn objects_only(
    v: &Value,
    shape: &Shape,
    at: &mut Vec<Seg>,
    root: &Value,
) -> Result<(), BakeError> {
    if v.is_array() {
        let what = match shape {
            Shape::Scene => "the scene",
            Shape::Mesh => "a mesh",
            Shape::Light => "a light",
            Shape::Object => "an object",
        };
        return Err(located(
            at,
            root,
            &format!("expected {what} written as an object {{\"name\": value, …}}, got a list (values by position are not accepted)"),
        ));
    }
    let Some(map) = v.as_object() else {
        return Ok(()); // serde names the wrong type
    };
    let inner = |key: &str, shape: Shape, each: bool, at: &mut Vec<Seg>| {
        let Some(x) = map.get(key) else { return Ok(()) };
        at.push(Seg::Key(key.into()));
        let r = match (each, x.as_array()) {
            (true, Some(items)) => items.iter().enumerate().try_for_each(|(i, item)| {
                at.push(Seg::Index(i));
                let r = objects_only(item, &shape, at, root);
                at.pop();
                r
            }),
            (true, None) => Ok(()),
            (false, _) => objects_only(x, &shape, at, root),
        };
        at.pop();
        r
    };
    match shape {
        Shape::Scene => {
            inner("meshes", Shape::Mesh, true, at)?;
            inner("lights", Shape::Light, true, at)?;
            inner("settings", Shape::Object, false, at)
        }
        Shape::Light => inner("spot", Shape::Object, false, at),
        Shape::Mesh | Shape::Object => Ok(()),
    }
}

fn segs(p: &serde_path_to_error::Path) -> Vec<Seg> {
    use serde_path_to_error::Segment;
    p.iter()
        .filter_map(|s| match s {
            Segment::Seq { index } => Some(Seg::Index(*index)),
            Segment::Map { key } => Some(Seg::Key(key.clone())),
            Segment::Enum { variant } => Some(Seg::Key(variant.clone())),
            Segment::Unknown => None,
        })
        .collect()
}

/// `a.b[3].c`
fn show(segs: &[Seg]) -> String {
    let mut s = String::new();
    for seg in segs {
        match seg {
            Seg::Key(k) if s.is_empty() => s.push_str(k),
            Seg::Key(k) => {
                s.push('.');
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// The error for the value at `at`: meshes and lights are named the way `validate` names
/// them (`mesh "Floor" (meshes[0]): polygons[0][3]: …`), settings as `settings.field`.
fn located(at: &[Seg], root: &Value, msg: &str) -> BakeError {
    // serde_json appends " at line L column C" when reading text; the path replaces it.
    let msg = match msg.rfind(" at line ") {
        Some(i) if msg[i..].contains(" column ") => &msg[..i],
        _ => msg,
    };
    // serde reports unknown and missing fields at their object: name the field itself.
    let named = ["unknown field `", "missing field `"]
        .iter()
        .find_map(|p| msg.strip_prefix(p))
        .and_then(|r| r.split('`').next())
        .map(|f| Seg::Key(f.to_string()));
    let mut full = at.to_vec();
    if let (Some(f), false) = (named, at.is_empty()) {
        full.push(f);
    }
    let at = full.as_slice();
    match at {
        [Seg::Key(list), Seg::Index(i), rest @ ..] if list == "meshes" || list == "lights" => {
            let kind = if list == "meshes" { "mesh" } else { "light" };
            let name = root
                .get(list)
                .and_then(|l| l.get(*i))
                .and_then(|o| o.get("name"))
                .and_then(Value::as_str);
            let object = match name {
                Some(n) => format!("{kind} {n:?} ({list}[{i}])"),
                None => format!("{kind} ({list}[{i}])"),
            };
            let field = if rest.is_empty() {
                String::new()
            } else {
                show(rest)
            };
            if field.is_empty() {
                BakeError::Format(format!("{object}: {msg}"))
            } else {
                BakeError::invalid(object, field, msg)
            }
        }
        [Seg::Key(s), rest @ ..] if s == "settings" && !rest.is_empty() => {
            BakeError::setting(show(rest), msg)
        }
        [] => BakeError::Format(msg.to_string()),
        _ => BakeError::Format(format!("{}: {msg}", show(at))),
    }
}

/// An entry of a colour list: a number (of a single `[r, g, b]`) or an `[r, g, b]`.
enum Entry {
    Number(f64),
    Rgb([f64; 3]),
}

impl<'de> Deserialize<'de> for Entry {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Entry;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or an [r, g, b] colour")
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Entry, E> {
                Ok(Entry::Number(x))
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<Entry, E> {
                Ok(Entry::Number(x as f64))
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<Entry, E> {
                Ok(Entry::Number(x as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Entry, A::Error> {
                let mut c = [0.0; 3];
                for (n, x) in c.iter_mut().enumerate() {
                    *x = seq.next_element()?.ok_or_else(|| {
                        de::Error::custom(format!("expected [r, g, b], got {n} numbers"))
                    })?;
                }
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(de::Error::custom(
                        "expected [r, g, b], got more than 3 numbers",
                    ));
                }
                Ok(Entry::Rgb(c))
            }
        }
        d.deserialize_any(V)
    }
}

/// `albedo`/`emission`: one `[r, g, b]` for the mesh, or a list of one `[r, g, b]` per
/// polygon. Written by hand because serde's untagged enum can only say "data did not match
/// any variant", and loses the index of the bad entry.
impl<'de> Deserialize<'de> for PerPolygon {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        const EXPECTED: &str =
            "expected one colour [r, g, b] for the mesh or a list [[r, g, b], …] of one per polygon";
        impl<'de> Visitor<'de> for V {
            type Value = PerPolygon;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(&EXPECTED["expected ".len()..])
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<PerPolygon, A::Error> {
                let mut numbers = Vec::new();
                let mut colours = Vec::new();
                while let Some(e) = seq.next_element::<Entry>()? {
                    match e {
                        Entry::Number(x) => numbers.push(x),
                        Entry::Rgb(c) => colours.push(c),
                    }
                    if !numbers.is_empty() && !colours.is_empty() {
                        return Err(de::Error::custom(format!(
                            "{EXPECTED}, got numbers and lists mixed"
                        )));
                    }
                }
                match (numbers.len(), colours.is_empty()) {
                    (0, _) => Ok(PerPolygon::PerPolygon(colours)),
                    (3, true) => Ok(PerPolygon::Uniform([numbers[0], numbers[1], numbers[2]])),
                    (n, _) => Err(de::Error::custom(format!("{EXPECTED}, got {n} numbers"))),
                }
            }
        }
        d.deserialize_seq(V)
    }
}

impl SceneJson {
    /// Parses scene JSON text (strictly: see `strict`) and checks `format` and `version`.
    pub fn from_str(text: &str) -> Result<Self, crate::BakeError> {
        let s = scene_from_str(text)?;
        if s.format != SCENE_FORMAT {
            return Err(crate::BakeError::Format(format!(
                "format is {:?}, expected {SCENE_FORMAT:?}",
                s.format
            )));
        }
        if s.version != SCENE_VERSION {
            return Err(crate::BakeError::Format(format!(
                "version {} is not supported (this build reads version {SCENE_VERSION})",
                s.version
            )));
        }
        Ok(s)
    }
}

#[cfg(test)]
mod test {
    use super::*;

    const GOOD: &str = r#"{"format":"penumbra-scene","version":1,
      "meshes":[{"name":"Floor","positions":[[0,0,0],[1,0,0],[1,1,0]],"polygons":[[0,1,2]]},
                {"name":"Box","positions":[[0,0,1],[1,0,1],[1,1,1]],"polygons":[[0,1,2]],
                 "albedo":[[0.5,0.5,0.5]]}],
      "lights":[{"name":"Sun","direction":[0,0,-1],"irradiance":[1,1,1]}],
      "settings":{"indirect":false}}"#;

    fn err(text: &str) -> String {
        scene_from_str(text).unwrap_err().to_string()
    }

    #[test]
    fn good_scene_reads() {
        let s = scene_from_str(GOOD).unwrap();
        assert_eq!(s.meshes.len(), 2);
        assert!(matches!(s.meshes[1].albedo, Some(PerPolygon::PerPolygon(ref v)) if v.len() == 1));
        let s = scene_from_str(&GOOD.replace("[[0.5,0.5,0.5]]", "[0.25,0.5,1]")).unwrap();
        assert!(matches!(
            s.meshes[1].albedo,
            Some(PerPolygon::Uniform([0.25, 0.5, 1.0]))
        ));
    }

    #[test]
    fn sequence_form_of_settings_is_refused() {
        let e = err(&GOOD.replace(r#"{"indirect":false}"#, "[0.05]"));
        assert!(e.contains("settings") && e.contains("got a list"), "{e}");
    }

    #[test]
    fn sequence_form_of_whole_scene_is_refused() {
        let e = err(
            r#"["penumbra-scene", 1, [["Floor", [[0,0,0],[1,0,0],[1,1,0]], [[0,1,2]]]], [], {}]"#,
        );
        assert!(e.contains("expected the scene written as an object"), "{e}");
        // ... and of one mesh, one light, one spot.
        let e = err(&GOOD.replace(
            r#"{"name":"Floor","positions":[[0,0,0],[1,0,0],[1,1,0]],"polygons":[[0,1,2]]}"#,
            r#"["Floor",[[0,0,0],[1,0,0],[1,1,0]],[[0,1,2]]]"#,
        ));
        assert!(
            e.contains("mesh (meshes[0])") && e.contains("got a list"),
            "{e}"
        );
        let e = err(&GOOD.replace(
            r#"{"name":"Sun","direction":[0,0,-1],"irradiance":[1,1,1]}"#,
            r#"{"name":"Spot","point":[0,0,3],"intensity":[1,1,1],"spot":[[0,0,-1],1.0]}"#,
        ));
        assert!(
            e.contains("lights[0]") && e.contains("spot") && e.contains("got a list"),
            "{e}"
        );
    }

    #[test]
    fn errors_name_object_and_path_not_line_and_column() {
        let e = err(&GOOD.replace("[[0.5,0.5,0.5]]", "[[0.5,0.5,0.5],[1,1],[1,1,1]]"));
        assert_eq!(
            e,
            r#"mesh "Box" (meshes[1]): albedo[1]: expected [r, g, b], got 2 numbers"#
        );
        let e = err(&GOOD.replace("[[0.5,0.5,0.5]]", r#"[[0.5,0.5,"grey"]]"#));
        assert!(
            e.starts_with(r#"mesh "Box" (meshes[1]): albedo[0][2]: invalid type: string"#),
            "{e}"
        );
        assert!(!e.contains("line"), "{e}");
        let e = err(&GOOD.replace(
            "[1,1,0]],\"polygons\":[[0,1,2]]},",
            "[1,\"x\",0]],\"polygons\":[[0,1,2]]},",
        ));
        assert!(
            e.starts_with(r#"mesh "Floor" (meshes[0]): positions[2][1]: invalid type"#),
            "{e}"
        );
        let e = err(&GOOD.replace(r#""indirect":false"#, r#""indirect":"no""#));
        assert!(
            e.starts_with("settings.indirect: invalid type: string"),
            "{e}"
        );
        // A number too large for f64 is caught while reading the text: still located.
        let e = err(&GOOD.replace(
            "[1,1,0]],\"polygons\":[[0,1,2]]},",
            "[1,1,1e400]],\"polygons\":[[0,1,2]]},",
        ));
        assert!(e.contains("meshes[0].positions[2][2]"), "{e}");
    }

    #[test]
    fn untagged_colour_error_says_what_was_expected() {
        for bad in [r#""grey""#, "[0.5,0.5]", "[[0.5,0.5,0.5],0.5]", "{}"] {
            let e = err(&GOOD.replace("[[0.5,0.5,0.5]]", bad));
            assert!(e.contains("albedo"), "{bad}: {e}");
            assert!(e.contains("[r, g, b]"), "{bad}: {e}");
            assert!(!e.contains("untagged"), "{bad}: {e}");
        }
    }

    #[test]
    fn huge_index_is_reported_as_written() {
        let e = err(&GOOD.replace("[[0,1,2]]}", "[[0,1,18446744073709551615]]}"));
        assert!(
            e.contains("meshes[0]") && e.contains("polygons[0][2]"),
            "{e}"
        );
        assert!(
            e.contains("18446744073709551615") && !e.contains("-1"),
            "{e}"
        );
    }

    #[test]
    fn values_from_the_binding_are_strict_too() {
        let e = settings_from_value(&serde_json::json!([0.05]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("got a list"), "{e}");
        let e = light_from_value(&serde_json::json!({"name": "Key", "point": [0, 0, "x"]}), 2)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(r#"light "Key" (lights[2]): point[2]: invalid type"#),
            "{e}"
        );
    }
}
