//! Unit tests of sheet-metal recognition from a boundary representation.
use super::*;
use std::f64::consts::{FRAC_PI_2, PI};

const T: f64 = 2.0;
const R: f64 = 3.0;
const W: f64 = 40.0;
const L1: f64 = 50.0;
const L2: f64 = 30.0;

fn line(a: [f64; 3], b: [f64; 3]) -> Segment {
    Segment::Line { start: DVec3::from_array(a), end: DVec3::from_array(b) }
}

fn polygon(points: &[[f64; 3]]) -> Vec<Segment> {
    (0..points.len()).map(|i| line(points[i], points[(i + 1) % points.len()])).collect()
}

fn plane(points: &[[f64; 3]], normal: [f64; 3], k: u64) -> BrepFace {
    BrepFace {
        source: FaceSource::Step { entity: k },
        surface: Surface::Plane { point: DVec3::from_array(points[0]), normal: DVec3::from_array(normal) },
        loops: vec![polygon(points)],
    }
}

/// An L profile in the x-z plane extruded along y over `[0, W]`: plate A (z in [0, T], x in [-L1, 0]), a 90
/// degree bend about the axis through (0, y, T + R), plate B (x in [R, R + T], up to z = T + R + L2). With
/// `hole`, plate A has a round hole of radius 5 at (-25, 20).
fn l_profile(hole: bool) -> Brep {
    let (t, r, big) = (T, R, R + T);
    let c = |y: f64| DVec3::new(0.0, y, t + r);
    let top = t + r + L2;
    let profile = |y: f64| -> Vec<Segment> {
        vec![
            line([-L1, y, 0.0], [0.0, y, 0.0]),
            Segment::Arc {
                center: c(y),
                axis: -DVec3::Y,
                radius: big,
                start: DVec3::new(0.0, y, 0.0),
                end: DVec3::new(big, y, t + r),
            },
            line([big, y, t + r], [big, y, top]),
            line([big, y, top], [r, y, top]),
            line([r, y, top], [r, y, t + r]),
            Segment::Arc {
                center: c(y),
                axis: DVec3::Y,
                radius: r,
                start: DVec3::new(r, y, t + r),
                end: DVec3::new(0.0, y, t),
            },
            line([0.0, y, t], [-L1, y, t]),
            line([-L1, y, t], [-L1, y, 0.0]),
        ]
    };
    let circle = |z: f64| Segment::Arc {
        center: DVec3::new(-25.0, 20.0, z),
        axis: DVec3::Z,
        radius: 5.0,
        start: DVec3::new(-20.0, 20.0, z),
        end: DVec3::new(-20.0, 20.0, z),
    };
    let mut a_bottom = plane(&[[-L1, 0.0, 0.0], [-L1, W, 0.0], [0.0, W, 0.0], [0.0, 0.0, 0.0]], [0.0, 0.0, -1.0], 1);
    let mut a_top = plane(&[[-L1, 0.0, t], [0.0, 0.0, t], [0.0, W, t], [-L1, W, t]], [0.0, 0.0, 1.0], 2);
    if hole {
        a_bottom.loops.push(vec![circle(0.0)]);
        a_top.loops.push(vec![circle(t)]);
    }
    let mut faces = vec![
        a_bottom,
        a_top,
        plane(&[[-L1, 0.0, 0.0], [-L1, 0.0, t], [-L1, W, t], [-L1, W, 0.0]], [-1.0, 0.0, 0.0], 3),
        plane(&[[r, 0.0, t + r], [r, 0.0, top], [r, W, top], [r, W, t + r]], [-1.0, 0.0, 0.0], 4),
        plane(&[[big, 0.0, t + r], [big, W, t + r], [big, W, top], [big, 0.0, top]], [1.0, 0.0, 0.0], 5),
        plane(&[[r, 0.0, top], [big, 0.0, top], [big, W, top], [r, W, top]], [0.0, 0.0, 1.0], 6),
        BrepFace {
            source: FaceSource::Step { entity: 7 },
            surface: Surface::Plane { point: DVec3::new(0.0, 0.0, 0.0), normal: -DVec3::Y },
            loops: vec![profile(0.0)],
        },
        BrepFace {
            source: FaceSource::Step { entity: 8 },
            surface: Surface::Plane { point: DVec3::new(0.0, W, 0.0), normal: DVec3::Y },
            loops: vec![profile(W)],
        },
        BrepFace {
            source: FaceSource::Step { entity: 9 },
            surface: Surface::Cylinder { point: c(0.0), axis: DVec3::Y, radius: r, convex: false },
            loops: vec![vec![
                line([0.0, 0.0, t], [0.0, W, t]),
                Segment::Arc {
                    center: c(W),
                    axis: -DVec3::Y,
                    radius: r,
                    start: DVec3::new(0.0, W, t),
                    end: DVec3::new(r, W, t + r),
                },
                line([r, W, t + r], [r, 0.0, t + r]),
                Segment::Arc {
                    center: c(0.0),
                    axis: DVec3::Y,
                    radius: r,
                    start: DVec3::new(r, 0.0, t + r),
                    end: DVec3::new(0.0, 0.0, t),
                },
            ]],
        },
        BrepFace {
            source: FaceSource::Step { entity: 10 },
            surface: Surface::Cylinder { point: c(0.0), axis: DVec3::Y, radius: big, convex: true },
            loops: vec![vec![
                line([0.0, 0.0, 0.0], [0.0, W, 0.0]),
                Segment::Arc {
                    center: c(W),
                    axis: -DVec3::Y,
                    radius: big,
                    start: DVec3::new(0.0, W, 0.0),
                    end: DVec3::new(big, W, t + r),
                },
                line([big, W, t + r], [big, 0.0, t + r]),
                Segment::Arc {
                    center: c(0.0),
                    axis: DVec3::Y,
                    radius: big,
                    start: DVec3::new(big, 0.0, t + r),
                    end: DVec3::new(0.0, 0.0, 0.0),
                },
            ]],
        },
    ];
    if hole {
        faces.push(BrepFace {
            source: FaceSource::Step { entity: 11 },
            surface: Surface::Cylinder {
                point: DVec3::new(-25.0, 20.0, 0.0),
                axis: DVec3::Z,
                radius: 5.0,
                convex: false,
            },
            loops: vec![vec![circle(0.0)], vec![circle(t)]],
        });
    }
    Brep { faces, volume: None, tessellation: None }
}

fn exact_volume(hole: bool) -> f64 {
    let bend = FRAC_PI_2 / 2.0 * ((R + T).powi(2) - R * R) * W;
    let hole = if hole { PI * 25.0 * T } else { 0.0 };
    (L1 + L2) * T * W + bend - hole
}

/// Whether `p` lies in the true solid.
fn in_solid(p: DVec3, hole: bool) -> bool {
    if !(0.0..=W).contains(&p.y) {
        return false;
    }
    if hole && (p.x + 25.0).powi(2) + (p.y - 20.0).powi(2) < 25.0 {
        return false;
    }
    let plate_a = (-L1..=0.0).contains(&p.x) && (0.0..=T).contains(&p.z);
    let plate_b = (R..=R + T).contains(&p.x) && (T + R..=T + R + L2).contains(&p.z);
    let (dx, dz) = (p.x, p.z - (T + R));
    let rho = (dx * dx + dz * dz).sqrt();
    let bend = dx >= 0.0 && dz <= 0.0 && (R..=R + T).contains(&rho);
    plate_a || plate_b || bend
}

#[test]
fn an_l_profile_gives_two_plates_one_bend_and_pieces_that_contain_it() {
    for hole in [false, true] {
        let (part, sheet) = recognise(&l_profile(hole), "l", &RecogniseOptions::default()).expect("recognised");
        assert!((sheet.thickness - T).abs() < 1e-12);
        assert_eq!(sheet.plates.len(), 2);
        assert_eq!(sheet.plates.iter().map(|p| p.holes).sum::<usize>(), usize::from(hole));
        assert_eq!(sheet.bends.len(), 1);
        let b = &sheet.bends[0];
        assert!((b.bend.inner_radius - R).abs() < 1e-12 && (b.bend.outer_radius - R - T).abs() < 1e-12);
        assert!((b.bend.angle - FRAC_PI_2).abs() < 1e-9, "angle {}", b.bend.angle);
        assert!((b.bend.axial[1] - b.bend.axial[0] - W).abs() < 1e-9);
        let exact = exact_volume(hole);
        assert!((sheet.solid_volume - exact).abs() < 1e-6 * exact, "{} vs {exact}", sheet.solid_volume);
        assert!(sheet.pieces_volume >= exact * (1.0 - 1e-12));
        assert!(sheet.pieces_volume <= exact * 1.01, "{} vs {exact}", sheet.pieces_volume);
        assert!(sheet.max_deviation <= DEFAULT_BEND_TOLERANCE + 1e-12 && sheet.max_deviation > 0.0);
        // every sampled point of the solid lies in a piece
        let comps = &part.components;
        let mut inside = 0;
        for i in 0..40 {
            for j in 0..12 {
                for k in 0..40 {
                    let p = DVec3::new(
                        -L1 + (L1 + R + T) * (i as f64 + 0.37) / 40.0,
                        W * (j as f64 + 0.41) / 12.0,
                        (T + R + L2) * (k as f64 + 0.29) / 40.0,
                    );
                    if in_solid(p, hole) {
                        inside += 1;
                        assert!(
                            comps.iter().any(|c| c.planes().all(|pl| pl.signed_distance(p) <= 1e-9)),
                            "{p} outside the pieces"
                        );
                    }
                }
            }
        }
        assert!(inside > 500);
    }
}

#[test]
fn a_block_is_no_sheet_and_the_error_names_the_faces() {
    // the L profile with plate B twice as thick on one side: its skins are 4 mm apart
    let mut brep = l_profile(false);
    for f in &mut brep.faces {
        if f.source == (FaceSource::Step { entity: 5 }) {
            for s in &mut f.loops[0] {
                if let Segment::Line { start, end } = s {
                    start.x += 2.0;
                    end.x += 2.0;
                }
            }
            f.surface = Surface::Plane { point: DVec3::new(R + T + 2.0, 0.0, T + R), normal: DVec3::X };
        }
    }
    let err = recognise(&brep, "l", &RecogniseOptions::default()).expect_err("not a sheet");
    let text = err.to_string();
    assert!(text.contains("--decompose"), "{text}");
    assert!(text.contains('#'), "{text}");
}
