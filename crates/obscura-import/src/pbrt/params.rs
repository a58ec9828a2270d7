//! pbrt-v4 parameter lists: `"type name" value` or `"type name" [values]`.

use crate::error::{ImportError, Location};
use std::cell::Cell;

/// One value of a parameter.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Value {
    Num(f64),
    Str(String),
    Bool(bool),
}

/// One parameter: its type, name and values, where it was written, and whether it was read.
#[derive(Clone, Debug)]
pub(crate) struct Param {
    pub(crate) ty: String,
    pub(crate) name: String,
    pub(crate) values: Vec<Value>,
    pub(crate) loc: Location,
    pub(crate) used: Cell<bool>,
}

/// A directive's parameters.
#[derive(Clone, Debug, Default)]
pub(crate) struct Params(pub(crate) Vec<Param>);

impl Params {
    fn find(&self, name: &str) -> Option<&Param> {
        let p = self.0.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// The parameter's numbers (of any numeric type).
    pub(crate) fn nums(&self, name: &str) -> Result<Option<Vec<f64>>, ImportError> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        p.values
            .iter()
            .map(|v| match v {
                Value::Num(x) => Ok(*x),
                _ => Err(p
                    .loc
                    .error(format!("parameter \"{}\": expected numbers", p.name))),
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }

    /// One number.
    pub(crate) fn num(&self, name: &str) -> Result<Option<f64>, ImportError> {
        match self.nums(name)? {
            None => Ok(None),
            Some(v) if v.len() == 1 => Ok(Some(v[0])),
            Some(v) => {
                let loc = &self.find(name).expect("found above").loc;
                Err(loc.error(format!(
                    "parameter \"{name}\": expected one number, got {}",
                    v.len()
                )))
            }
        }
    }

    /// One number, else `default`.
    pub(crate) fn num_or(&self, name: &str, default: f64) -> Result<f64, ImportError> {
        Ok(self.num(name)?.unwrap_or(default))
    }

    /// Exactly `n` numbers.
    pub(crate) fn fixed<const N: usize>(
        &self,
        name: &str,
    ) -> Result<Option<[f64; N]>, ImportError> {
        match self.nums(name)? {
            None => Ok(None),
            Some(v) => {
                let loc = self.find(name).expect("found above").loc.clone();
                v.try_into().map(Some).map_err(|v: Vec<f64>| {
                    loc.error(format!(
                        "parameter \"{name}\": expected {N} numbers, got {}",
                        v.len()
                    ))
                })
            }
        }
    }

    /// One string.
    pub(crate) fn string(&self, name: &str) -> Result<Option<String>, ImportError> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        match p.values.as_slice() {
            [Value::Str(s)] => Ok(Some(s.clone())),
            _ => Err(p
                .loc
                .error(format!("parameter \"{name}\": expected one string"))),
        }
    }

    /// One bool (`true`, `false`, or the strings "true" and "false").
    pub(crate) fn boolean(&self, name: &str) -> Result<Option<bool>, ImportError> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        match p.values.as_slice() {
            [Value::Bool(b)] => Ok(Some(*b)),
            [Value::Str(s)] if s == "true" || s == "false" => Ok(Some(s == "true")),
            _ => Err(p
                .loc
                .error(format!("parameter \"{name}\": expected true or false"))),
        }
    }

    /// A colour given as `rgb`; other spectrum forms (`spectrum`, `blackbody`, textures) are
    /// the caller's `fallback` with a warning.
    pub(crate) fn rgb(
        &self,
        name: &str,
        warnings: &mut Vec<String>,
    ) -> Result<Option<[f64; 3]>, ImportError> {
        let Some(p) = self.0.iter().find(|p| p.name == name) else {
            return Ok(None);
        };
        match p.ty.as_str() {
            "rgb" | "color" => self.fixed::<3>(name),
            "float" => Ok(self.num(name)?.map(|v| [v; 3])),
            other => {
                p.used.set(true);
                warnings.push(format!(
                    "{}: parameter \"{name}\": a {other} value is not supported (only rgb); using the default",
                    p.loc
                ));
                Ok(None)
            }
        }
    }

    /// The type a parameter was given with.
    pub(crate) fn type_of(&self, name: &str) -> Option<&str> {
        self.0
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.ty.as_str())
    }

    /// Warnings for parameters nothing read.
    pub(crate) fn unused(&self, directive: &str, warnings: &mut Vec<String>) {
        for p in self.0.iter().filter(|p| !p.used.get()) {
            warnings.push(format!(
                "{}: {directive}: parameter \"{} {}\" is not supported and was ignored",
                p.loc, p.ty, p.name
            ));
        }
    }
}
