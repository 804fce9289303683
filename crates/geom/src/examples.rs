//! Built-in example parts: the three test parts of \[A\] Fig. 14, the unit cube of \[A\] Fig. 2, and the L-shaped
//! corner and block of \[P\] (Pan & Schimmels 2004, Fig. 1). All lengths in millimetres.
//!
//! The seed gives no dimensions, only pictures and component counts (\[A\] sec. 7, Tables 1 and 2: Channel 3,
//! Triangle 6, Complex 79 convex components). The sheet-metal parts below are modelled to reproduce those counts
//! exactly with [`Decomposition::Triangulation`] (the seed's scheme: convex faces extruded whole, concave faces and
//! faces with holes triangulated, `n + 2h - 2` triangles for `n` vertices and `h` holes), and to have the features
//! the seed describes (nesting by flipping for the channel, nesting in one orientation for the triangle part, tall
//! flanges for the complex part). The tests in `tests/decomposition.rs` check the counts.

use crate::hull::convex_hull;
use crate::part::{Part, PartOrigin};
use crate::sheet_metal::{Decomposition, SheetFace, SheetMetal};
use glam::DVec3;

/// Sheet thickness of the sheet-metal examples (mm).
pub const THICKNESS: f64 = 2.0;

/// Names accepted by [`part_by_name`] and [`by_name`].
pub const NAMES: [&str; 6] = ["channel", "triangle", "complex", "cube", "l-corner", "block"];

/// An example: either a sheet-metal model or a solid part given as convex pieces.
#[derive(Debug, Clone, PartialEq)]
pub enum Example {
    /// A zero-thickness sheet-metal model (build it with [`SheetMetal::build_part`]).
    SheetMetal(SheetMetal),
    /// A solid part.
    Solid(Box<Part>),
}

impl Example {
    /// The part (sheet-metal models built with `decomposition`, density 1).
    pub fn part(&self, name: &str, decomposition: Decomposition) -> Part {
        match self {
            Example::SheetMetal(s) => s
                .build_part(name, 1.0, decomposition)
                .expect("built-in sheet-metal examples are valid (checked by tests/decomposition.rs)"),
            Example::Solid(p) => (**p).clone(),
        }
    }
}

/// The example called `name` (one of [`NAMES`]; `_` and `-` are interchangeable).
pub fn by_name(name: &str) -> Option<Example> {
    match name.replace('_', "-").as_str() {
        "channel" => Some(Example::SheetMetal(channel())),
        "triangle" => Some(Example::SheetMetal(triangle())),
        "complex" => Some(Example::SheetMetal(complex())),
        "cube" => Some(Example::Solid(Box::new(cube()))),
        "l-corner" => Some(Example::Solid(Box::new(l_corner_part()))),
        "block" => Some(Example::Solid(Box::new(block_part()))),
        _ => None,
    }
}

/// The example part called `name`, sheet-metal models decomposed with `decomposition` (density 1).
pub fn part_by_name(name: &str, decomposition: Decomposition) -> Option<Part> {
    let canonical = name.replace('_', "-");
    by_name(&canonical).map(|e| e.part(&canonical, decomposition))
}

fn face(outline: Vec<DVec3>) -> SheetFace {
    SheetFace { outline, holes: Vec::new() }
}

fn p(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// Channel Part (\[A\] Fig. 14a): a U channel of three convex faces, so 3 components with either decomposition.
///
/// Mid-surface: base `[0, 200] x [0, 100]` in `z = 0`; two side flanges bent up by 90 degrees along the long edges,
/// in the planes `y = 0` and `y = 100`, 50 high. Thickness 2. The seed calls it a part with "three flanges" and
/// counts 3 convex components, so the web counts as one of the three. With vertical flanges, copies nest only
/// when alternate parts are flipped (a flipped channel straddles one flange of the one below), as in the seed.
pub fn channel() -> SheetMetal {
    let base = face(vec![p(0.0, 0.0, 0.0), p(200.0, 0.0, 0.0), p(200.0, 100.0, 0.0), p(0.0, 100.0, 0.0)]);
    let front = face(vec![p(0.0, 0.0, 0.0), p(200.0, 0.0, 0.0), p(200.0, 0.0, 50.0), p(0.0, 0.0, 50.0)]);
    let back = face(vec![p(0.0, 100.0, 0.0), p(200.0, 100.0, 0.0), p(200.0, 100.0, 50.0), p(0.0, 100.0, 50.0)]);
    SheetMetal { thickness: THICKNESS, faces: vec![base, front, back] }
}

/// Triangle Part (\[A\] Fig. 14b): six flanges, all convex, so 6 components with either decomposition.
///
/// An open triangular hopper: three trapezoidal walls splayed outwards and three horizontal lips around the rim.
/// The walls join an equilateral triangle of inradius 30 at `z = 0` to one of inradius 50 at `z = 40` (each wall
/// leans outwards by `atan(1/2)` = 26.6 degrees from the vertical); the lips run from the rim out to an equilateral
/// triangle of inradius 65 in `z = 40` (15 wide). The triangles are centred on the z axis with a vertex on +y.
/// Thickness 2. Identical copies nest in the same orientation: a copy lowered onto another stops when its walls
/// meet the walls below, `t * sqrt(5) = 4.47` mm higher (a vertical shift `dz` puts the wall planes `dz / sqrt(5)`
/// apart), far less than the part height of 40.
pub fn triangle() -> SheetMetal {
    let corner = |inradius: f64, k: usize, z: f64| {
        let angle = std::f64::consts::FRAC_PI_2 + k as f64 * 2.0 * std::f64::consts::FRAC_PI_3;
        let circumradius = 2.0 * inradius;
        p(circumradius * angle.cos(), circumradius * angle.sin(), z)
    };
    let mut faces = Vec::with_capacity(6);
    for k in 0..3 {
        let j = (k + 1) % 3;
        faces.push(face(vec![
            corner(30.0, k, 0.0),
            corner(30.0, j, 0.0),
            corner(50.0, j, 40.0),
            corner(50.0, k, 40.0),
        ]));
    }
    for k in 0..3 {
        let j = (k + 1) % 3;
        faces.push(face(vec![
            corner(50.0, k, 40.0),
            corner(50.0, j, 40.0),
            corner(65.0, j, 40.0),
            corner(65.0, k, 40.0),
        ]));
    }
    SheetMetal { thickness: THICKNESS, faces }
}

fn rect_xy(x0: f64, y0: f64, x1: f64, y1: f64, z: f64) -> Vec<DVec3> {
    vec![p(x0, y0, z), p(x1, y0, z), p(x1, y1, z), p(x0, y1, z)]
}

fn rect_yz(x: f64, y0: f64, z0: f64, y1: f64, z1: f64) -> Vec<DVec3> {
    vec![p(x, y0, z0), p(x, y1, z0), p(x, y1, z1), p(x, y0, z1)]
}

/// Complex Part (\[A\] Fig. 8 and 14c): a base with holes, two tall flanges with windows, two short flanges and a lip;
/// 79 components with the plain triangulation, as in the seed.
///
/// Mid-surface (thickness 2):
/// * base `[0, 300] x [0, 200]` in `z = 0` with six rectangular holes 30 x 20 (lower-left corners at
///   `x in {50, 135, 220}`, `y in {40, 140}`) and a regular octagonal hole of circumradius 25 centred at
///   `(150, 100)`: `n = 4 + 6 * 4 + 8 = 36` vertices, `h = 7` holes, `36 + 14 - 2 = 48` triangles;
/// * two tall flanges, 150 high, bent up along `x = 0` and `x = 300` over `y in [20, 180]`, each with two
///   rectangular windows `y in [40, 80]` and `[120, 160]`, `z in [60, 120]`: `12 + 4 - 2 = 14` triangles each;
/// * two short flanges, 30 high, along `y = 0` and `y = 200` over the full length: convex, 1 component each;
/// * a lip bent outwards at the top of the tall flange at `x = 0`: `[-30, 0] x [20, 180]` in `z = 150`: 1.
///
/// Total `48 + 2 * 14 + 2 + 1 = 79`. How it was tuned: the count of a face is `n + 2h - 2` (or 1 when convex), so
/// the layout was chosen by that arithmetic, not by trial; the test `complex_part_counts` confirms it.
pub fn complex() -> SheetMetal {
    let mut base_holes = Vec::new();
    for x in [50.0, 135.0, 220.0] {
        for y in [40.0, 140.0] {
            base_holes.push(rect_xy(x, y, x + 30.0, y + 20.0, 0.0));
        }
    }
    base_holes.push(
        (0..8)
            .map(|k| {
                let a = k as f64 * std::f64::consts::FRAC_PI_4;
                p(150.0 + 25.0 * a.cos(), 100.0 + 25.0 * a.sin(), 0.0)
            })
            .collect(),
    );
    let base = SheetFace { outline: rect_xy(0.0, 0.0, 300.0, 200.0, 0.0), holes: base_holes };
    let tall = |x: f64| SheetFace {
        outline: rect_yz(x, 20.0, 0.0, 180.0, 150.0),
        holes: vec![rect_yz(x, 40.0, 60.0, 80.0, 120.0), rect_yz(x, 120.0, 60.0, 160.0, 120.0)],
    };
    let short_front = face(vec![p(0.0, 0.0, 0.0), p(300.0, 0.0, 0.0), p(300.0, 0.0, 30.0), p(0.0, 0.0, 30.0)]);
    let short_back = face(vec![p(0.0, 200.0, 0.0), p(300.0, 200.0, 0.0), p(300.0, 200.0, 30.0), p(0.0, 200.0, 30.0)]);
    let lip = face(rect_xy(-30.0, 20.0, 0.0, 180.0, 150.0));
    SheetMetal { thickness: THICKNESS, faces: vec![base, tall(0.0), tall(300.0), short_front, short_back, lip] }
}

fn cuboid(lo: DVec3, hi: DVec3) -> crate::polytope::ConvexPolytope {
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    convex_hull(&corners).expect("a box with positive extent has a 3-D hull").polytope
}

fn solid(name: &str, boxes: &[(DVec3, DVec3)]) -> Part {
    let components = boxes.iter().map(|&(lo, hi)| cuboid(lo, hi)).collect();
    Part::from_components(name, components, 1.0, PartOrigin::ConvexPieces)
        .expect("boxes with positive volume make a part")
}

/// The unit cube of \[A\] Fig. 2 (the 121-cube stacks): `[0, 1]^3` mm, one component.
pub fn cube() -> Part {
    solid("cube", &[(DVec3::ZERO, DVec3::ONE)])
}

/// The L-shaped corner of \[P\] Fig. 1 (the fixed part of the contact-state example), as three disjoint boxes:
/// a floor `[0, 150] x [0, 150] x [0, 20]`, a wall `[0, 20] x [0, 150] x [20, 120]` and a wall
/// `[20, 150] x [0, 20] x [20, 120]`. Seen from above the walls form an L; the block is inserted into the corner
/// from the top. The seed gives no dimensions; these leave the block of [`block_part`] 50 mm of play either way.
pub fn l_corner_part() -> Part {
    solid(
        "l-corner",
        &[
            (p(0.0, 0.0, 0.0), p(150.0, 150.0, 20.0)),
            (p(0.0, 0.0, 20.0), p(20.0, 150.0, 120.0)),
            (p(20.0, 0.0, 20.0), p(150.0, 20.0, 120.0)),
        ],
    )
}

/// The rectangular block of \[P\] Fig. 1 (the moving part): `[0, 80] x [0, 80] x [0, 100]`, one component.
pub fn block_part() -> Part {
    solid("block", &[(DVec3::ZERO, p(80.0, 80.0, 100.0))])
}
