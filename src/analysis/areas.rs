//! Barycentric cell areas (Kloiber thesis, Fig. 3.9).
//!
//! A vertex's cell in a triangle is bounded by the vertex, the midpoints of
//! its two edges and the triangle's centroid; the three cells of a triangle
//! are equal, so each is a third of the triangle's area. The hierarchy uses
//! these areas to weight merges, and the averaging of quantities over
//! surfaces can use them as densities.

use crate::mesh::TriMesh;

/// Area of every vertex's barycentric cell (0 for vertices without faces).
/// The areas sum to the mesh's total area.
pub fn barycentric_cell_areas(mesh: &TriMesh) -> Vec<f64> {
    let mut areas = vec![0.0; mesh.vertex_count()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let third = mesh.face_area(f) / 3.0;
        for &v in t {
            areas[v as usize] += third;
        }
    }
    areas
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn cells_partition_the_surface() {
        let m = generate::flat_grid(1.0, 10);
        let areas = barycentric_cell_areas(&m);
        let total: f64 = areas.iter().sum();
        assert!((total - 4.0).abs() < 1e-12);
        // An interior vertex of a regular grid owns one cell's worth of area.
        let interior = 5 * 11 + 5;
        assert!((areas[interior] - 0.04).abs() < 1e-12);
    }
}
