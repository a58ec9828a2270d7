use glam::Vec3;
use obscura_accel::{Placement, SceneBuilder, Shape};
use obscura_space::{Point3, Transform, Vector3};
fn main() {
    let mut b = SceneBuilder::new();
    let fixed = || Placement::Static(Transform::IDENTITY);
    b.add(Shape::Quad { origin: Vec3::new(-1.0, -1.0, 0.0), edge_u: Vec3::X * 2.0, edge_v: Vec3::Y * 2.0 }, fixed()).unwrap();
    b.add(Shape::Sphere { center: Vec3::new(0.0, 0.0, 3.0), radius: 1.0 }, fixed()).unwrap();
    let scene = b.build().unwrap();
    let down = obscura_space::Ray::new(Point3::new(0.0, 0.0, 1.5), Vector3::new(0.0, 0.0, -1.0), 0.0);
    let hit = scene.intersect(&down).unwrap();
    println!("{hit:?}");
    let s = hit.spawn_ray_to(Point3::new(0.0, 0.0, 2.0));
    println!("{s:?} {:?}", scene.intersect(&s));
}
