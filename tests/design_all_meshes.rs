//! The design session and its analysis (Campen & Kobbelt 2014, §4.1, §4.2,
//! §6, §7) on every shared mesh — closed, open, several components, scans,
//! CAD: three hover proposals committed one after the other, each followed
//! by the analysis the page draws. Nothing may panic; every analysis must
//! say what it found (a status line), every loop must embed, and when it
//! reports a layout on a closed connected mesh, its V − E + F must equal
//! the surface's Euler characteristic.

mod common;

use quadrille::layout::design::LayoutDesign;
use quadrille::layout::{ElasticaParams, LoopEngine, proxy};
use quadrille::web::layout_glue::analyze;

#[test]
fn three_strips_on_every_shared_mesh() {
    let started = std::time::Instant::now();
    let clock = move || started.elapsed().as_secs_f64() * 1e3;
    for name in common::ALL {
        let input = common::mesh(name);
        let mesh = if input.face_count() > proxy::PROXY_ABOVE_FACES {
            proxy::decimate(&input, proxy::PROXY_FACES)
        } else {
            input
        };
        let topology = mesh.topology();
        let mut design = LayoutDesign::new(LoopEngine::new(&mesh, &ElasticaParams::default()));
        let n = mesh.vertex_count();
        let mut committed = 0;
        for k in 0..6 {
            if committed == 3 {
                break;
            }
            let p = mesh.positions[(k * 7919 + 11) % n];
            if design.hover(p).is_none() || design.commit().is_err() {
                continue;
            }
            committed += 1;
            let a = analyze(&mesh, &mut design, &clock);
            assert!(!a.status.is_empty(), "{name}: no status");
            // Every committed loop embeds (thin parts, boundary ends) and the
            // parametrization solves; the regions are found on every
            // mesh but the teapot (a non-manifold vertex: its region
            // boundaries do not close, reported in the status).
            assert!(!a.status.contains("jumps between"), "{name}: {}", a.status);
            assert!(
                !a.status.contains("no parametrization"),
                "{name}: {}",
                a.status
            );
            if name != "teapot.obj" {
                assert!(
                    !a.status.contains("could not be found"),
                    "{name}: {}",
                    a.status
                );
            }
            let c = &a.counts;
            if c.patches > 0 && topology.boundary_edges == 0 && topology.components == 1 {
                let chi = c.layout_vertices as i64 - c.layout_edges as i64 + c.patches as i64;
                assert_eq!(
                    chi, topology.euler_characteristic,
                    "{name}: layout V − E + F"
                );
            }
            println!(
                "{name} ({} faces), {committed} strips: {}",
                mesh.face_count(),
                a.status
            );
        }
        assert!(committed > 0, "{name}: no strip could be committed");
    }
}
