//! The viewer's pick (the surface point under the pointer, on every hover in
//! the design mode) goes through a BVH; it must answer what testing every
//! triangle answers, on real meshes: the bunny (curved, fine) and fandisk
//! (large flat faces).

mod common;

use glam::Vec3;
use quadrille::web::mesh_arrays::vertex_normals;
use quadrille::web::viewer::scene::Surface;
use rand_core::{RngCore, SeedableRng};

fn surface(name: &str) -> Surface {
    let mesh = common::mesh(name);
    let positions: Vec<f32> = mesh
        .positions
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let triangles: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    Surface::new(&positions, &triangles, &vertex_normals(&mesh)).unwrap()
}

fn unit(rng: &mut rand_pcg::Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

fn on_sphere(rng: &mut rand_pcg::Pcg32) -> Vec3 {
    loop {
        let v = Vec3::new(unit(rng), unit(rng), unit(rng)) * 2.0 - Vec3::ONE;
        if (0.01..=1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    }
}

/// Rays from outside the bounding sphere toward points on the surface
/// (jittered) and toward points in its bounding box (some miss): the BVH's
/// hit is the exhaustive one. Where two triangles are hit at the same
/// distance (through a shared edge or corner) either may be reported.
fn bvh_pick_is_the_exhaustive_pick(name: &str) {
    let s = surface(name);
    let (center, radius) = s.bounding_sphere().unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(21);
    let (mut hits, mut misses, mut ties) = (0, 0, 0);
    for i in 0..3000 {
        let origin = center + on_sphere(&mut rng) * radius * (1.5 + 2.0 * unit(&mut rng));
        let target = if i % 4 == 0 {
            center
                + (Vec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) * 2.0 - Vec3::ONE)
                    * radius
        } else {
            let t = s.triangles[rng.next_u32() as usize % s.triangles.len()];
            let (u, v) = (unit(&mut rng), unit(&mut rng));
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let [a, b, c] = t.map(|k| s.positions[k as usize]);
            a + (b - a) * u + (c - a) * v + on_sphere(&mut rng) * radius * 1e-3
        };
        let dir = target - origin;
        match (s.pick(origin, dir), s.pick_exhaustive(origin, dir)) {
            (None, None) => misses += 1,
            (Some(b), Some(e)) => {
                hits += 1;
                if b.triangle != e.triangle {
                    assert!(
                        (b.distance - e.distance).abs() <= 1e-5 * e.distance,
                        "{name}, ray {i}: the BVH hit triangle {} at {}, the exhaustive pick {} at {}",
                        b.triangle,
                        b.distance,
                        e.triangle,
                        e.distance
                    );
                    ties += 1;
                } else {
                    assert_eq!(b, e, "{name}, ray {i}");
                }
            }
            (b, e) => panic!("{name}, ray {i}: the BVH pick {b:?}, the exhaustive one {e:?}"),
        }
    }
    assert!(
        hits > 2000 && misses > 50,
        "{name}: {hits} hits, {misses} misses"
    );
    assert!(ties <= hits / 100, "{name}: {ties} ties in {hits} hits");
}

#[test]
fn the_bunny_is_picked_as_by_testing_every_triangle() {
    bvh_pick_is_the_exhaustive_pick("stanford-bunny.obj");
}

#[test]
fn fandisk_is_picked_as_by_testing_every_triangle() {
    bvh_pick_is_the_exhaustive_pick("fandisk.obj");
}

/// Rays that meet nothing, or carry no direction, pick nothing.
#[test]
fn bad_rays_pick_nothing() {
    let s = surface("fandisk.obj");
    let (center, radius) = s.bounding_sphere().unwrap();
    let away = center + Vec3::X * 3.0 * radius;
    assert_eq!(s.pick(away, Vec3::X), None);
    assert_eq!(s.pick(away, Vec3::ZERO), None);
    assert_eq!(s.pick(away, Vec3::new(f32::NAN, 0.0, 0.0)), None);
    assert_eq!(s.pick(Vec3::splat(f32::INFINITY), -Vec3::X), None);
}
