//! A key given twice in one JSON object is refused: `serde_json::Value` (and any map) keeps the
//! last value without a word, so a scene or checkpoint edited by hand would run with the value
//! further down the file. Checked on the text before it is parsed into a `Value`; serde's
//! derived objects refuse a duplicate field themselves.

use serde::de::{DeserializeSeed, Deserializer, Error as _, MapAccess, SeqAccess, Visitor};

use crate::error::{Error, Result};

/// Refuses JSON `text` holding an object with a key given twice, naming the key's path
/// (`blocks[1].density`). Text that is not JSON passes: the parser that follows says where.
///
/// # Errors
/// [`Error::Checkpoint`] with the path of the second occurrence.
pub fn refuse_duplicate_keys(text: &str) -> Result<()> {
    let mut de = serde_json::Deserializer::from_str(text);
    let mut path = Vec::new();
    let mut found = None;
    let _ = Walk {
        path: &mut path,
        found: &mut found,
    }
    .deserialize(&mut de);
    match found {
        Some((path, key)) => Err(Error::Checkpoint {
            path,
            message: format!("duplicate key `{key}`: a key may be given once in an object (which value was meant?)"),
        }),
        None => Ok(()),
    }
}

/// One segment of a path: a key or an index.
enum Segment {
    Key(String),
    Index(usize),
}

fn joined(path: &[Segment]) -> String {
    let mut out = String::new();
    for s in path {
        match s {
            Segment::Key(k) => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(k);
            }
            Segment::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

/// Walks a value, recording the first duplicate key (path, key) and stopping there.
struct Walk<'a> {
    path: &'a mut Vec<Segment>,
    found: &'a mut Option<(String, String)>,
}

impl<'de> DeserializeSeed<'de> for Walk<'_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, de: D) -> std::result::Result<(), D::Error> {
        de.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Walk<'_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> std::result::Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> std::result::Result<(), E> {
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<(), A::Error> {
        let mut i = 0;
        loop {
            self.path.push(Segment::Index(i));
            let more = seq.next_element_seed(Walk {
                path: self.path,
                found: self.found,
            })?;
            self.path.pop();
            if more.is_none() {
                return Ok(());
            }
            i += 1;
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<(), A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            if !seen.insert(key.clone()) {
                self.path.push(Segment::Key(key.clone()));
                *self.found = Some((joined(self.path), key));
                return Err(A::Error::custom("duplicate key"));
            }
            self.path.push(Segment::Key(key));
            map.next_value_seed(Walk {
                path: self.path,
                found: self.found,
            })?;
            self.path.pop();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::refuse_duplicate_keys;

    #[test]
    fn names_the_path_of_the_second_key() {
        assert!(refuse_duplicate_keys(r#"{"a": 1, "b": [{"c": 2}, {"c": 3}]}"#).is_ok());
        let e = refuse_duplicate_keys(r#"{"a": 1, "b": [{"c": 2}, {"c": 3, "d": {"e": 1, "e": 2}}]}"#).unwrap_err();
        assert!(
            e.to_string().contains("b[1].d.e") && e.to_string().contains("duplicate key `e`"),
            "{e}"
        );
        let e = refuse_duplicate_keys(r#"{"a": 1, "a": 1}"#).unwrap_err();
        assert!(e.to_string().contains("`a`"), "{e}");
        // Escaped keys compare by their value.
        assert!(refuse_duplicate_keys(r#"{"a": 1, "\u0061": 2}"#).is_err());
        // Not JSON: passes, for the parser to say where.
        assert!(refuse_duplicate_keys("{nope").is_ok());
    }
}
