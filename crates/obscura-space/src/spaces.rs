//! The glossary of coordinate spaces.
//!
//! Each space is an empty, uninhabited type used only as a tag. A value such as
//! `Point3<Camera>` says in its type which space it lives in, so the compiler refuses to add a
//! world-space vector to a camera-space point. Users may add their own spaces by implementing
//! [`Space`] for an empty type of theirs.

/// A coordinate space tag. Implement it for your own empty type to add a space.
pub trait Space: 'static {
    /// A short name used by `Debug` output, e.g. `"World"`.
    const NAME: &'static str;
}

macro_rules! spaces {
    ($($(#[$doc:meta])* $name:ident),* $(,)?) => {$(
        $(#[$doc])*
        #[derive(Debug)]
        pub enum $name {}
        impl Space for $name {
            const NAME: &'static str = stringify!($name);
        }
    )*};
}

spaces! {
    /// The scene's world space: right-handed; `up` is whatever the scene says.
    World,
    /// An object's own modelling space, before its instance transform.
    Object,
    /// Camera space: origin at the camera, +z along the view, +y up, +x towards the image's
    /// right. With a right-handed world this frame is left-handed: `camera_from_world` is a
    /// reflection (determinant -1).
    Camera,
    /// Screen space of a projective camera: the image plane, with z = 0 on the near plane and
    /// z = 1 on the far plane.
    Screen,
    /// Normalised device coordinates: x and y in [0, 1] across the screen window, y down.
    Ndc,
    /// Raster space: x in [0, width], y in [0, height], y down; pixel (i, j) has its centre at
    /// (i + 0.5, j + 0.5).
    Raster,
}
