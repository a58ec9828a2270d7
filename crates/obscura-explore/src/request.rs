//! Reading what a request carries, its JSON body and its query, so that every error names the
//! key at fault (docs/explorer.md: an error is `{"error", "key"}`).
//!
//! A JSON body is read with a seed that notes the dotted path of the object key whose value
//! is being read (`camera.fov`), so even an error from the JSON parser itself, such as a
//! number out of range (`1e400`), names the key it was reading.

use crate::error::ExploreError;
use axum::extract::{FromRequestParts, Query};
use axum::http::request::Parts;
use serde::de::{DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::Value as Json;
use std::cell::RefCell;
use std::collections::HashMap;
use std::fmt;

/// Parses JSON text. On failure: the dotted path of the object key whose value was being read
/// (None outside every object's values, as for a syntax error between keys) and serde's
/// message.
pub(crate) fn parse_keyed(text: &[u8]) -> Result<Json, (Option<String>, String)> {
    let at = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_slice(text);
    let value = Keyed {
        at: &at,
        path: None,
    }
    .deserialize(&mut de)
    .and_then(|v| de.end().map(|()| v));
    value.map_err(|e| (at.into_inner(), e.to_string()))
}

/// A JSON value at `path`, noting in `at` the path of each object key as its value is read.
struct Keyed<'a> {
    at: &'a RefCell<Option<String>>,
    path: Option<String>,
}

impl<'de> DeserializeSeed<'de> for Keyed<'_> {
    type Value = Json;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Json, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Keyed<'_> {
    type Value = Json;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Json, A::Error> {
        let mut out = serde_json::Map::new();
        while let Some(key) = map.next_key::<String>()? {
            let path = match &self.path {
                Some(p) => format!("{p}.{key}"),
                None => key.clone(),
            };
            *self.at.borrow_mut() = Some(path.clone());
            let value = map.next_value_seed(Keyed {
                at: self.at,
                path: Some(path),
            })?;
            // Past the value: an error now (a missing comma) is this object's.
            self.at.borrow_mut().clone_from(&self.path);
            out.insert(key, value);
        }
        Ok(Json::Object(out))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Json, A::Error> {
        // Elements are named by their array's key.
        let mut out = Vec::new();
        while let Some(v) = seq.next_element_seed(Keyed {
            at: self.at,
            path: self.path.clone(),
        })? {
            out.push(v);
        }
        Ok(Json::Array(out))
    }

    fn visit_bool<E>(self, v: bool) -> Result<Json, E> {
        Ok(Json::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Json, E> {
        Ok(Json::from(v))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Json, E> {
        Ok(Json::from(v))
    }

    fn visit_f64<E>(self, v: f64) -> Result<Json, E> {
        // JSON text holds no infinity or NaN; the parser refuses numbers out of f64's range.
        Ok(serde_json::Number::from_f64(v).map_or(Json::Null, Json::Number))
    }

    fn visit_str<E>(self, v: &str) -> Result<Json, E> {
        Ok(Json::String(v.to_owned()))
    }

    fn visit_string<E>(self, v: String) -> Result<Json, E> {
        Ok(Json::String(v))
    }

    fn visit_unit<E>(self) -> Result<Json, E> {
        Ok(Json::Null)
    }
}

/// A raster position from a JSON body `{"x": X, "y": Y}`, each finite.
pub(crate) fn pixel(body: &[u8]) -> Result<(f32, f32), ExploreError> {
    let value = parse_keyed(body).map_err(|(key, message)| keyed(key, message))?;
    let Json::Object(fields) = value else {
        return Err(ExploreError::BadRequest(format!(
            "a pixel is a JSON object {{\"x\": X, \"y\": Y}} (raster), got {value}"
        )));
    };
    if let Some(other) = fields.keys().find(|k| *k != "x" && *k != "y") {
        return Err(ExploreError::Malformed {
            key: other.clone(),
            message: "unknown field; a pixel has x and y (raster)".into(),
        });
    }
    let coordinate = |key: &str| -> Result<f32, ExploreError> {
        let malformed = |message: String| ExploreError::Malformed {
            key: key.into(),
            message,
        };
        match fields.get(key) {
            None => Err(malformed("missing (a raster coordinate)".into())),
            Some(v) => v
                .as_f64()
                .map(|v| v as f32)
                .filter(|v| v.is_finite())
                .ok_or_else(|| malformed(format!("must be a finite number (raster), got {v}"))),
        }
    };
    Ok((coordinate("x")?, coordinate("y")?))
}

/// A parse error as the explorer's: naming the key when one was being read.
pub(crate) fn keyed(key: Option<String>, message: String) -> ExploreError {
    match key {
        Some(key) => ExploreError::Malformed { key, message },
        None => ExploreError::BadRequest(message),
    }
}

/// A request's query parameters (`?session=ID&x=X`), each read with an error naming it.
pub(crate) struct Params(HashMap<String, String>);

impl<S: Send + Sync> FromRequestParts<S> for Params {
    type Rejection = ExploreError;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Params, ExploreError> {
        Query::<HashMap<String, String>>::try_from_uri(&parts.uri)
            .map(|Query(q)| Params(q))
            .map_err(|e| ExploreError::BadRequest(e.body_text()))
    }
}

impl Params {
    /// `session`, where given.
    pub(crate) fn session(&self) -> Result<Option<u64>, ExploreError> {
        self.0
            .get("session")
            .map(|s| {
                s.parse().map_err(|_| ExploreError::Malformed {
                    key: "session".into(),
                    message: format!("must be a session number, got {s:?}"),
                })
            })
            .transpose()
    }

    /// `session`, which the request needs.
    pub(crate) fn required_session(&self) -> Result<u64, ExploreError> {
        self.session()?.ok_or_else(|| ExploreError::Malformed {
            key: "session".into(),
            message: "missing: name the page's session, ?session=ID".into(),
        })
    }

    /// The finite number `key`, which the request needs.
    pub(crate) fn finite(&self, key: &str) -> Result<f32, ExploreError> {
        let text = self.text(key)?;
        text.parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| ExploreError::Malformed {
                key: key.into(),
                message: format!("must be a finite number, got {text:?}"),
            })
    }

    /// The text of `key`, which the request needs.
    pub(crate) fn text(&self, key: &str) -> Result<&str, ExploreError> {
        self.0
            .get(key)
            .map(String::as_str)
            .ok_or_else(|| ExploreError::Malformed {
                key: key.into(),
                message: "missing".into(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_parse_error_names_the_key_being_read() {
        for (text, key) in [
            (r#"{"camera": {"fov": 1e400}}"#, Some("camera.fov")),
            (r#"{"camera": {"eye": [0, 1e400, 0]}}"#, Some("camera.eye")),
            (
                r#"{"camera": {"stereo": {"interaxial": -1e999}}}"#,
                Some("camera.stereo.interaxial"),
            ),
            (r#"{"camera": {"fov": "#, Some("camera.fov")),
            (r#"{"camera": {"fov": 1} "spp": 2}"#, None),
            (r#"{"camera": {"fov": 1, "near" 2}}"#, Some("camera.near")),
            (r#"{"camera": {"fov": 1 "near": 2}}"#, Some("camera")),
            (r#"{"spp": 1} x"#, None),
            ("not json", None),
        ] {
            let (got, message) = parse_keyed(text.as_bytes()).unwrap_err();
            assert_eq!(got.as_deref(), key, "{text}: {message}");
        }
    }

    #[test]
    fn a_parse_keeps_the_values() {
        let text = r#"{"camera": {"fov": 30.5, "eye": [1, -2, 3e2], "type": "ods",
            "stereo": {"interaxial": 0.1}, "x": null, "b": true}, "spp": 4}"#;
        let want: Json = serde_json::from_str(text).unwrap();
        assert_eq!(parse_keyed(text.as_bytes()).unwrap(), want);
    }
}
