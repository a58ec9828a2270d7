//! Integration tests of obscura-accel: the BVH against a brute-force f64 reference, moving
//! instances, OBJ files good and bad, and self-intersection of spawned rays.

mod batch;
mod brute;
mod exact;
mod obj_files;
mod reference;
mod spawn;
mod testmesh;
