//! Integration tests of obscura-space: round trips, composition, look-at, animated transforms
//! and their motion bounds, and degenerate input.
//!
//! Tolerances. f32 carries 24 bits (epsilon 1.19e-7). A matrix-vector product of entries bounded
//! by `|M|` on a point of size `|p|` rounds to within about 4 eps |M| |p|; going there and back
//! multiplies by the condition number. The strategies below keep scales in [1/4, 4] and
//! translations within 100, so the condition number stays below ~16 x 3 composed factors; a
//! relative tolerance of 2e-5 of the values' magnitude covers that with a wide margin while still
//! catching any real error (a wrong transpose or sign moves results by O(1)).

mod animated;
mod transform;

use obscura_space::{Space, Transform};
use proptest::prelude::*;

/// Asserts two glam vectors agree within `tol * scale`.
#[track_caller]
pub fn assert_close(a: glam::Vec3, b: glam::Vec3, scale: f32) {
    let tol = 2e-5 * scale.max(1.0);
    assert!(
        (a - b).abs().max_element() <= tol,
        "{a:?} != {b:?} (tolerance {tol})"
    );
}

/// A vector with components in [-r, r].
pub fn vec3(r: f32) -> impl Strategy<Value = glam::Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| glam::Vec3::new(x, y, z))
}

/// A non-degenerate direction (length in [0.5, 1]).
pub fn axis() -> impl Strategy<Value = glam::Vec3> {
    vec3(1.0).prop_filter("axis too short", |v| v.length() > 0.5)
}

/// A scale factor in +-[1/4, 4].
fn factor() -> impl Strategy<Value = f32> {
    (0.25f32..4.0, any::<bool>()).prop_map(|(f, neg)| if neg { -f } else { f })
}

/// One random scale, rotation or translation.
pub fn elementary<A: Space, B: Space>() -> impl Strategy<Value = Transform<A, B>> {
    prop_oneof![
        (factor(), factor(), factor())
            .prop_map(|(x, y, z)| Transform::scale(glam::Vec3::new(x, y, z)).unwrap()),
        (-360.0f32..360.0, axis()).prop_map(|(deg, axis)| Transform::rotate(deg, axis).unwrap()),
        vec3(100.0).prop_map(|t| Transform::translate(t).unwrap()),
    ]
}

/// A composition of three elementary transforms.
pub fn transform<A: Space, B: Space>() -> impl Strategy<Value = Transform<A, B>> {
    (
        elementary::<A, B>(),
        elementary::<B, B>(),
        elementary::<B, B>(),
    )
        .prop_map(|(a, b, c)| a * b * c)
}
