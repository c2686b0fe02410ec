//! Scene and checkpoint documents between `Model<AnyLaw>` (the package's model) and the Rust
//! models of one law type: laws named with their kind on the way in, written without it when
//! every law is Coulomb's; files read with the library's bounded reader.

use pyo3::prelude::*;
use voussoir::io::scene::Scene;
use voussoir::law::{AnyLaw, CoulombSlip};
use voussoir::Error;

use crate::errors::OrPy;

/// A scene or checkpoint document of a model with one law type, as one of `Model<AnyLaw>`: a
/// law without its kind (`{"normal_stiffness": ..}` of a `Scene<CoulombSlip>`) is named
/// (`{"Coulomb": ..}`, `{"Mortar": ..}` with a softening shape, or `{"Elastic": ..}` without a
/// friction angle), and so is a sub-contact's law state.
pub(crate) fn as_any_law(doc: &mut serde_json::Value) {
    use serde_json::Value;
    fn wrap_law(law: &mut Value) {
        if let Value::Object(map) = law {
            if !["Coulomb", "Mortar", "Elastic"].iter().any(|k| map.contains_key(*k)) {
                let kind = if map.contains_key("softening") {
                    "Mortar"
                } else if map.contains_key("friction_deg") {
                    "Coulomb"
                } else {
                    "Elastic"
                };
                *law = serde_json::json!({ kind: law.take() });
            }
        }
    }
    // Scenes: joints[k].law.
    if let Some(Value::Array(joints)) = doc.get_mut("joints") {
        for j in joints {
            if let Some(law) = j.get_mut("law") {
                wrap_law(law);
            }
        }
    }
    // Checkpoints: joints.laws[k], contacts[k].subcontacts[j].state.
    if let Some(Value::Array(laws)) = doc.get_mut("joints").and_then(|j| j.get_mut("laws")) {
        for law in laws {
            wrap_law(law);
        }
    }
    if let Some(Value::Array(contacts)) = doc.get_mut("contacts") {
        for c in contacts {
            if let Some(Value::Array(subs)) = c.get_mut("subcontacts") {
                for s in subs {
                    if let Some(state) = s.get_mut("state") {
                        match state {
                            Value::Null => *state = serde_json::json!({}),
                            Value::Object(m) if !m.contains_key("coulomb") && m.contains_key("failed") => {
                                *state = serde_json::json!({ "coulomb": state.take() });
                            }
                            Value::Object(m) if !m.contains_key("mortar") && m.contains_key("crack_opening") => {
                                *state = serde_json::json!({ "mortar": state.take() });
                            }
                            _ => {}
                        }
                    }
                }
            }
        }
    }
}

/// Parses JSON text for [`as_any_law`]; on a syntax error, `None` (the typed parser then
/// reports it with its own message).
pub(crate) fn normalised(text: &str) -> Option<String> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut doc: serde_json::Value = serde_json::from_str(text).ok()?;
    as_any_law(&mut doc);
    serde_json::to_string(&doc).ok()
}

pub(crate) fn read(path: &std::path::Path) -> PyResult<String> {
    voussoir::io::read_text(path).py()
}

/// A scene of `Model<AnyLaw>` as JSON, written as a `Scene<CoulombSlip>` when every law is
/// Coulomb's (what a Rust program with the default `Model` reads).
pub(crate) fn scene_json(scene: &Scene<AnyLaw>) -> voussoir::Result<String> {
    let laws: Option<Vec<CoulombSlip>> = scene
        .joints
        .iter()
        .map(|j| match j.law {
            AnyLaw::Coulomb(c) => Some(c),
            _ => None,
        })
        .collect();
    let text = scene.to_json()?;
    if laws.is_none() {
        return Ok(text);
    }
    let mut doc: serde_json::Value = serde_json::from_str(&text).map_err(|e| Error::Io {
        path: "(scene)".into(),
        message: e.to_string(),
    })?;
    if let Some(serde_json::Value::Array(joints)) = doc.get_mut("joints") {
        for j in joints {
            if let Some(law) = j.get_mut("law") {
                if let Some(inner) = law.get_mut("Coulomb").map(serde_json::Value::take) {
                    *law = inner;
                }
            }
        }
    }
    serde_json::to_string_pretty(&doc).map_err(|e| Error::Io {
        path: "(scene)".into(),
        message: e.to_string(),
    })
}
