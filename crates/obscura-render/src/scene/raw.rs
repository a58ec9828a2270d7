//! The scene file's raw serde structs: what TOML gives before any check. Unknown keys are
//! errors, and so is an array of the wrong length, too long as well as too short ([`fixed`]).

use super::settings::V3;
use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scene file of tables")]
pub(super) struct RawScene {
    #[serde(deserialize_with = "table::one")]
    pub(super) film: RawFilm,
    #[serde(default, deserialize_with = "table::one")]
    pub(super) sampler: RawSampler,
    #[serde(default, deserialize_with = "table::one")]
    pub(super) integrator: RawIntegrator,
    #[serde(deserialize_with = "table::one")]
    pub(super) camera: RawCamera,
    #[serde(default, deserialize_with = "table::named")]
    pub(super) materials: BTreeMap<String, RawMaterial>,
    #[serde(default, deserialize_with = "table::many")]
    pub(super) shapes: Vec<RawShape>,
    #[serde(default, deserialize_with = "table::many")]
    pub(super) lights: Vec<RawLight>,
}

/// The camera's part of a scene file: the tables of [`RawScene`] a camera reads. Keys and
/// tables outside them are skipped, not denied (serde's default), so that a scene the renderer
/// refuses elsewhere still gives its camera; the tables read keep their `deny_unknown_fields`.
#[derive(Deserialize)]
#[serde(expecting = "a scene file of tables")]
pub(super) struct RawCameraPart {
    #[serde(deserialize_with = "table::one")]
    pub(super) film: RawFilm,
    #[serde(default, deserialize_with = "table::one")]
    pub(super) sampler: RawSamplerType,
    #[serde(deserialize_with = "table::one")]
    pub(super) camera: RawCamera,
}

/// `[sampler] type` alone: the other sampler keys set up a render, not the camera, and are
/// skipped. (`expecting` keeps this struct's name out of a message such as `sampler = 5`'s.)
#[derive(Deserialize, Default)]
#[serde(expecting = "a table")]
pub(super) struct RawSamplerType {
    #[serde(rename = "type")]
    pub(super) kind: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawFilm {
    #[serde(deserialize_with = "fixed::exact")]
    pub(super) resolution: [u32; 2],
    pub(super) filter: Option<toml::Value>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) crop: Option<[f32; 4]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawSampler {
    #[serde(rename = "type")]
    pub(super) kind: Option<String>,
    pub(super) spp: Option<u32>,
    pub(super) seed: Option<u64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawIntegrator {
    #[serde(rename = "type")]
    pub(super) kind: Option<String>,
    pub(super) max_depth: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawCamera {
    #[serde(rename = "type")]
    pub(super) kind: Option<String>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) eye: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) target: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) up: Option<V3>,
    pub(super) fov: Option<f32>,
    pub(super) fov_axis: Option<String>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) screen_window: Option<[f32; 4]>,
    pub(super) near: Option<f32>,
    pub(super) far: Option<f32>,
    pub(super) lens_radius: Option<f32>,
    pub(super) focal_distance: Option<f32>,
    pub(super) aperture_blades: Option<u32>,
    pub(super) aperture_rotation: Option<f32>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) shutter: Option<[f32; 2]>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) eye_end: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) target_end: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) up_end: Option<V3>,
    pub(super) fx: Option<f64>,
    pub(super) fy: Option<f64>,
    pub(super) cx: Option<f64>,
    pub(super) cy: Option<f64>,
    pub(super) distortion: Option<Vec<f64>>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) rvec: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) tvec: Option<[f64; 3]>,
    pub(super) projection: Option<String>,
    pub(super) face: Option<String>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) lens_shift: Option<[f32; 2]>,
    #[serde(default, deserialize_with = "table::optional")]
    pub(super) stereo: Option<RawStereo>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) pose: Option<[f32; 16]>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) pose_end: Option<[f32; 16]>,
    pub(super) lens_file: Option<String>,
    pub(super) aperture_diameter: Option<f32>,
    pub(super) focus_distance: Option<f32>,
    pub(super) film_diagonal: Option<f32>,
    pub(super) aperture_image: Option<String>,
    pub(super) anamorphic: Option<f32>,
    #[serde(default, deserialize_with = "fixed::optional_list")]
    pub(super) shutter_curve: Option<Vec<[f32; 2]>>,
    #[serde(default, deserialize_with = "table::optional")]
    pub(super) rolling_shutter: Option<RawRollingShutter>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) focal_plane_tilt: Option<[f32; 2]>,
    pub(super) f_number: Option<f32>,
    pub(super) shutter_time: Option<f32>,
    pub(super) iso: Option<f32>,
    pub(super) exposure_compensation: Option<f32>,
    pub(super) focal_length: Option<f32>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table such as { readout = 0.5, direction = \"top_to_bottom\" }"
)]
pub(super) struct RawRollingShutter {
    pub(super) readout: Option<f32>,
    pub(super) direction: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawStereo {
    pub(super) interaxial: Option<f32>,
    pub(super) convergence: Option<f32>,
    pub(super) layout: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawMaterial {
    #[serde(rename = "type")]
    pub(super) kind: String,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) reflectance: Option<V3>,
    pub(super) ior: Option<f32>,
    pub(super) roughness: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawShape {
    #[serde(rename = "type")]
    pub(super) kind: String,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) center: Option<V3>,
    pub(super) radius: Option<f32>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) origin: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) edge_u: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) edge_v: Option<V3>,
    pub(super) file: Option<String>,
    pub(super) material: Option<String>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) emission: Option<V3>,
    #[serde(default, deserialize_with = "table::optional_many")]
    pub(super) transform: Option<Vec<RawOp>>,
    #[serde(default, deserialize_with = "table::optional_many")]
    pub(super) transform_end: Option<Vec<RawOp>>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table such as { translate = [0, 1, 0] }"
)]
pub(super) struct RawOp {
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) scale: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) rotate: Option<[f32; 4]>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) translate: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) matrix: Option<[f32; 16]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table")]
pub(super) struct RawLight {
    #[serde(rename = "type")]
    pub(super) kind: String,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) position: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) intensity: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) direction: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) irradiance: Option<V3>,
    #[serde(default, deserialize_with = "fixed::optional")]
    pub(super) radiance: Option<V3>,
    pub(super) file: Option<String>,
    #[serde(default, deserialize_with = "table::optional_many")]
    pub(super) transform: Option<Vec<RawOp>>,
}

/// Tables only. Serde also fills a struct from an array, by position
/// (`stereo = [0.1, 5.0, "separate"]`), which the scene format does not have: these read a
/// table's keys and refuse any other value with "expected a table".
pub(super) mod table {
    use serde::de::value::MapAccessDeserializer;
    use serde::de::{Deserialize, Deserializer, MapAccess, Visitor};
    use std::collections::BTreeMap;
    use std::fmt;
    use std::marker::PhantomData;

    /// Accepts a table only, and reads `T` from its keys.
    struct OnlyTable<T>(PhantomData<T>);

    impl<'de, T: Deserialize<'de>> Visitor<'de> for OnlyTable<T> {
        type Value = T;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a table")
        }

        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
            T::deserialize(MapAccessDeserializer::new(map))
        }
    }

    /// `T` read from a table only, as an element of an array or a map.
    struct Tabled<T>(T);

    impl<'de, T: Deserialize<'de>> Deserialize<'de> for Tabled<T> {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            one(d).map(Tabled)
        }
    }

    /// A table.
    pub(in crate::scene) fn one<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        d: D,
    ) -> Result<T, D::Error> {
        d.deserialize_map(OnlyTable(PhantomData))
    }

    /// A table, when the key is given.
    pub(in crate::scene) fn optional<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        d: D,
    ) -> Result<Option<T>, D::Error> {
        one(d).map(Some)
    }

    /// An array of tables.
    pub(in crate::scene) fn many<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        d: D,
    ) -> Result<Vec<T>, D::Error> {
        Vec::<Tabled<T>>::deserialize(d).map(|v| v.into_iter().map(|t| t.0).collect())
    }

    /// An array of tables, when the key is given.
    pub(in crate::scene) fn optional_many<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        d: D,
    ) -> Result<Option<Vec<T>>, D::Error> {
        many(d).map(Some)
    }

    /// A table of tables, by name.
    pub(in crate::scene) fn named<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        d: D,
    ) -> Result<BTreeMap<String, T>, D::Error> {
        BTreeMap::<String, Tabled<T>>::deserialize(d)
            .map(|m| m.into_iter().map(|(k, t)| (k, t.0)).collect())
    }
}

/// Fixed-length arrays that refuse extra entries as well as missing ones: the `toml` crate's
/// deserializer hands serde's `[T; N]` the first `N` entries of a longer array and drops the
/// rest without a word, so `eye = [0, 0, 5, 7]` would pass as `[0, 0, 5]`.
pub(super) mod fixed {
    use serde::de::{Deserialize, Deserializer, Error, SeqAccess, Visitor};
    use std::fmt;
    use std::marker::PhantomData;

    /// An array of exactly `N` entries.
    struct Exact<T, const N: usize>([T; N]);

    impl<'de, T: Deserialize<'de>, const N: usize> Deserialize<'de> for Exact<T, N> {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            d.deserialize_seq(ExactVisitor::<T, N>(PhantomData))
        }
    }

    struct ExactVisitor<T, const N: usize>(PhantomData<T>);

    impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for ExactVisitor<T, N> {
        type Value = Exact<T, N>;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "an array of length {N}")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut entries = Vec::with_capacity(N);
            while let Some(entry) = seq.next_element()? {
                entries.push(entry);
            }
            let len = entries.len();
            let array: [T; N] = entries
                .try_into()
                .map_err(|_| A::Error::invalid_length(len, &self))?;
            Ok(Exact(array))
        }
    }

    /// A required `[T; N]`.
    pub(super) fn exact<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
    where
        D: Deserializer<'de>,
        T: Deserialize<'de>,
    {
        Exact::<T, N>::deserialize(d).map(|e| e.0)
    }

    /// An optional `[T; N]` (with `#[serde(default)]`, so a missing key is `None`).
    pub(super) fn optional<'de, D, T, const N: usize>(d: D) -> Result<Option<[T; N]>, D::Error>
    where
        D: Deserializer<'de>,
        T: Deserialize<'de>,
    {
        Option::<Exact<T, N>>::deserialize(d).map(|o| o.map(|e| e.0))
    }

    /// An optional list of `[T; N]`.
    pub(super) fn optional_list<'de, D, T, const N: usize>(
        d: D,
    ) -> Result<Option<Vec<[T; N]>>, D::Error>
    where
        D: Deserializer<'de>,
        T: Deserialize<'de>,
    {
        Option::<Vec<Exact<T, N>>>::deserialize(d)
            .map(|o| o.map(|list| list.into_iter().map(|e| e.0).collect()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[derive(Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    struct Probe {
        #[serde(deserialize_with = "fixed::exact")]
        v: [f32; 3],
        #[serde(default, deserialize_with = "fixed::optional")]
        o: Option<[u32; 2]>,
        #[serde(default, deserialize_with = "fixed::optional_list")]
        l: Option<Vec<[f32; 2]>>,
    }

    fn list(values: &[f32]) -> String {
        let v: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
        format!("[{}]", v.join(", "))
    }

    proptest! {
        /// Exactly three entries read back as written; any other count is refused and the
        /// message gives the count found.
        #[test]
        fn fixed_arrays_take_exactly_their_length(
            values in proptest::collection::vec(-1e6f32..1e6, 0..8)
        ) {
            let parsed = toml::from_str::<Probe>(&format!("v = {}", list(&values)));
            if values.len() == 3 {
                prop_assert_eq!(parsed.unwrap().v.to_vec(), values);
            } else {
                let message = parsed.unwrap_err().message().to_string();
                let expected = format!("invalid length {}, expected an array of length 3", values.len());
                prop_assert!(message.contains(&expected), "{}", message);
            }
        }
    }

    #[test]
    fn optional_arrays_and_lists_check_their_length_too() {
        let p: Probe = toml::from_str("v = [1, 2, 3]").unwrap();
        assert!(p.o.is_none() && p.l.is_none());
        let p: Probe = toml::from_str("v = [1, 2, 3]\no = [4, 5]\nl = [[0, 1], [1, 0.5]]").unwrap();
        assert_eq!(p.o, Some([4, 5]));
        assert_eq!(p.l, Some(vec![[0.0, 1.0], [1.0, 0.5]]));
        for bad in [
            "o = [4, 5, 6]",
            "o = [4]",
            "l = [[0, 1], [1, 0.5, 2]]",
            "l = [[0]]",
        ] {
            let e = toml::from_str::<Probe>(&format!("v = [1, 2, 3]\n{bad}")).unwrap_err();
            assert!(e.message().contains("invalid length"), "{bad}: {e}");
        }
    }
}
