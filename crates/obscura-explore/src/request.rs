//! Reading what a request carries, its JSON body and its query, so that every error names the
//! key at fault (docs/explorer.md: an error is `{"error", "key"}`).
//!
//! A JSON body is read through `serde_path_to_error`, which notes the path of the value being
//! read (`camera.fov`), so even an error from the JSON parser itself, such as a number out of
//! range (`1e400`), names the key it was reading.

use crate::error::ExploreError;
use axum::extract::{FromRequestParts, Query};
use axum::http::request::Parts;
use serde_json::Value as Json;
use serde_path_to_error::Segment;
use std::collections::HashMap;

/// Parses JSON text. On failure: the dotted path of the object key whose value was being read
/// (None outside every object's values, as for a syntax error between keys; an array's
/// elements are named by the array's key) and serde's message.
pub(crate) fn parse_keyed(text: &[u8]) -> Result<Json, (Option<String>, String)> {
    let mut de = serde_json::Deserializer::from_slice(text);
    let value = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let keys: Vec<&str> = e
            .path()
            .iter()
            .filter_map(|s| match s {
                Segment::Map { key } => Some(key.as_str()),
                _ => None,
            })
            .collect();
        let key = (!keys.is_empty()).then(|| keys.join("."));
        (key, e.into_inner().to_string())
    })?;
    de.end().map_err(|e| (None, e.to_string()))?;
    Ok(value)
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

    /// The text of `key`, where given.
    pub(crate) fn optional(&self, key: &str) -> Option<&str> {
        self.0.get(key).map(String::as_str)
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
            (r#"{"camera": {"fov": 1, "near" 2}}"#, Some("camera")),
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
