//! Colormaps for scalar quantities, as in polyscope: a sequential map for
//! magnitudes (curvature, sizing field) and a violet–green diverging map for
//! signed values (limit-surface error), both perceptually ordered.

use serde::Serialize;

/// A named colormap: colours sampled at evenly spaced stops, interpolated linearly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Colormap {
    /// Sequential dark violet → yellow (matplotlib's viridis).
    Viridis,
    /// Diverging violet → white → green (ColorBrewer PRGn), centred on the range's middle.
    VioletGreen,
    /// Face degree over [3, 6]: triangles orange, quads pale grey-blue,
    /// pentagons violet, six and more red (each degree hits a stop exactly).
    FaceDegree,
    /// Categories over [0, 12]: 0 grey (none), 1–12 twelve distinct colours
    /// (ColorBrewer Paired), for region ids.
    Categories,
}

const VIRIDIS: [u32; 10] = [
    0x440154, 0x482878, 0x3e4989, 0x31688e, 0x26828e, 0x1f9e89, 0x35b779, 0x6ece58, 0xb5de2b,
    0xfde725,
];
const FACE_DEGREE: [u32; 4] = [0xf28e2b, 0xd5dbe6, 0x8e44ad, 0xc0392b];
const CATEGORIES: [u32; 13] = [
    0xbdbdbd, 0xa6cee3, 0x1f78b4, 0xb2df8a, 0x33a02c, 0xfb9a99, 0xe31a1c, 0xfdbf6f, 0xff7f00,
    0xcab2d6, 0x6a3d9a, 0xffff99, 0xb15928,
];
const VIOLET_GREEN: [u32; 11] = [
    0x40004b, 0x762a83, 0x9970ab, 0xc2a5cf, 0xe7d4e8, 0xf7f7f7, 0xd9f0d3, 0xa6dba0, 0x5aae61,
    0x1b7837, 0x00441b,
];

impl Colormap {
    /// By name: `viridis` or `violet-green` (case-insensitive).
    pub fn from_name(name: &str) -> Option<Colormap> {
        match name.to_ascii_lowercase().as_str() {
            "viridis" => Some(Colormap::Viridis),
            "violet-green" | "violetgreen" | "diverging" => Some(Colormap::VioletGreen),
            "face-degree" => Some(Colormap::FaceDegree),
            "categories" => Some(Colormap::Categories),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Colormap::Viridis => "viridis",
            Colormap::VioletGreen => "violet-green",
            Colormap::FaceDegree => "face-degree",
            Colormap::Categories => "categories",
        }
    }

    fn stops(self) -> &'static [u32] {
        match self {
            Colormap::Viridis => &VIRIDIS,
            Colormap::VioletGreen => &VIOLET_GREEN,
            Colormap::FaceDegree => &FACE_DEGREE,
            Colormap::Categories => &CATEGORIES,
        }
    }

    /// Colour at `t` in [0, 1] (clamped; NaN gives the middle), as sRGB bytes.
    pub fn sample(self, t: f32) -> [u8; 3] {
        let stops = self.stops();
        let t = if t.is_nan() { 0.5 } else { t.clamp(0.0, 1.0) };
        let x = t * (stops.len() - 1) as f32;
        let i = (x.floor() as usize).min(stops.len() - 2);
        let f = x - i as f32;
        let (a, b) = (rgb(stops[i]), rgb(stops[i + 1]));
        let mix = |k: usize| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * f).round() as u8;
        [mix(0), mix(1), mix(2)]
    }

    /// The stops as CSS colours, for an HTML legend (`linear-gradient`).
    pub fn css_stops(self) -> Vec<String> {
        self.stops().iter().map(|c| format!("#{c:06x}")).collect()
    }
}

fn rgb(c: u32) -> [u8; 3] {
    [(c >> 16) as u8, (c >> 8) as u8, c as u8]
}

/// The range shown by a legend: `[min, max]` with `min < max`, widened when
/// the values are constant and replaced by `[0, 1]` when nothing is finite.
pub fn finite_range(values: &[f32]) -> (f32, f32) {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for &v in values.iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    if lo == hi {
        let pad = if lo == 0.0 { 1.0 } else { lo.abs() * 0.5 };
        return (lo - pad, hi + pad);
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_middle() {
        assert_eq!(Colormap::Viridis.sample(0.0), [0x44, 0x01, 0x54]);
        assert_eq!(Colormap::Viridis.sample(1.0), [0xfd, 0xe7, 0x25]);
        assert_eq!(Colormap::VioletGreen.sample(0.5), [0xf7, 0xf7, 0xf7]);
        assert_eq!(
            Colormap::Viridis.sample(-3.0),
            Colormap::Viridis.sample(0.0)
        );
        assert_eq!(
            Colormap::Viridis.sample(f32::NAN),
            Colormap::Viridis.sample(0.5)
        );
    }

    #[test]
    fn ranges() {
        assert_eq!(
            finite_range(&[1.0, f32::NAN, -2.0, f32::INFINITY]),
            (-2.0, 1.0)
        );
        assert_eq!(finite_range(&[]), (0.0, 1.0));
        let (lo, hi) = finite_range(&[3.0, 3.0]);
        assert!(lo < 3.0 && hi > 3.0);
    }

    #[test]
    fn names_round_trip() {
        for c in [
            Colormap::Viridis,
            Colormap::VioletGreen,
            Colormap::FaceDegree,
            Colormap::Categories,
        ] {
            assert_eq!(Colormap::from_name(c.name()), Some(c));
        }
        assert_eq!(Colormap::from_name("jet"), None);
    }
}
