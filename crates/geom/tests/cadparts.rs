//! The STEP parts of `fixtures/cad/` (made with OpenCASCADE by `make_fixtures.py`): faces on cones, tori, B-spline
//! surfaces (rational and not) and extrusions, tessellated and recognised through the mesh route, against what the
//! script says they are; the tessellation's volume against the exact one; points of the exact solid inside the
//! pieces; and damaged entities giving errors that name them.

use stackplan_geom::cad::recognise::Recognition;
use stackplan_geom::io::step::{DEFAULT_CHORD_TOLERANCE, StepOptions, parse_step, read_step};
use stackplan_geom::io::{IoError, Place, ReadOptions, sheet::read_sheet};
use stackplan_geom::{DVec3, Part};
use std::path::{Path, PathBuf};

fn path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/cad").join(format!("{name}.step"))
}

fn facts(name: &str) -> serde_json::Value {
    let file = path(name).with_extension("json");
    serde_json::from_str(&std::fs::read_to_string(&file).expect("facts")).expect("json")
}

fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("{key}"))
}

fn sheet(name: &str) -> (Part, Recognition) {
    read_sheet(path(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn each_part_is_recognised_as_its_script_says() {
    for name in ["countersink_plate", "flange_nurbs", "spline_plate"] {
        let f = facts(name);
        let (part, r) = sheet(name);
        let t = r.tessellation.unwrap_or_else(|| panic!("{name}: not tessellated"));
        assert!(t.curved_faces >= 1 && t.curved_faces <= t.faces, "{name}: {t:?}");
        assert!((t.chord_tolerance - 0.025).abs() < 1e-15, "{name}: a quarter of the default bend tolerance");
        assert!((r.thickness - num(&f, "thickness")).abs() <= 1e-6, "{name}: thickness {}", r.thickness);
        assert_eq!(r.plates.len() as f64, num(&f, "plates"), "{name}: plates");
        assert_eq!(r.plates.iter().map(|p| p.holes).sum::<usize>() as f64, num(&f, "holes"), "{name}: holes");
        assert_eq!(r.bends.len() as f64, num(&f, "bends"), "{name}: bends");
        let radii = f["bend_radii"].as_array().expect("radii");
        for (b, want) in r.bends.iter().zip(radii) {
            let want = want.as_f64().expect("radius");
            // fitted to the facets' generators, which lie on the exact (rational B-spline) cylinder
            assert!((b.bend.inner_radius - want).abs() <= 1e-6, "{name}: radius {}", b.bend.inner_radius);
            if let Some(angle) = f["bend_angle_degrees"].as_f64() {
                assert!((b.bend.angle.to_degrees() - angle).abs() <= 1e-6, "{name}: angle {}", b.bend.angle);
            }
        }
        if let Some(area) = f["plate_area"].as_f64() {
            // the mesh's holes and curved outline are chords within the chord tolerance of the exact curves
            let got: f64 = r.plates.iter().map(|p| p.area).sum();
            assert!((got - area).abs() <= 1e-3 * area, "{name}: plate area {got} vs {area}");
        }
        // the pieces contain the mesh, which is within the chord tolerance of the solid
        let v = num(&f, "volume");
        let slack = t.chord_tolerance * num(&f, "area");
        assert!(part.mass().volume >= v - slack, "{name}: pieces {} below the solid's {v}", part.mass().volume);
        assert!(part.mass().volume <= v * 1.02, "{name}: pieces {} vs the solid's {v}", part.mass().volume);
        if name == "countersink_plate" {
            // the plate fills the countersinks' cones: up to (11 - 5.5) / 2 mm out of the solid, and says so
            assert!((2.75..=2.85).contains(&r.max_deviation), "{name}: {}", r.max_deviation);
        } else {
            assert!(r.max_deviation <= r.bend_tolerance + 1e-12, "{name}: {} > {}", r.max_deviation, r.bend_tolerance);
        }
        assert!(r.max_deviation >= t.chord_tolerance, "{name}: the deviation includes the chord tolerance");
    }
}

#[test]
fn the_tessellations_are_closed_and_hold_the_exact_volume_within_the_chord_bound() {
    for name in ["countersink_plate", "flange_nurbs", "spline_plate", "flanged_hole"] {
        let f = facts(name);
        for chord in [DEFAULT_CHORD_TOLERANCE, 0.005] {
            let options = StepOptions { chord_tolerance: Some(chord), ..StepOptions::default() };
            // mesh_faces would have refused a mesh that is not closed and manifold
            let brep = read_step(path(name), &options).unwrap_or_else(|e| panic!("{name}: {e}"));
            let t = brep.tessellation.expect("tessellated");
            assert_eq!(t.chord_tolerance, chord);
            let volume = brep.volume.expect("the mesh's volume");
            let exact = num(&f, "volume");
            let bound = chord * num(&f, "area");
            assert!((volume - exact).abs() <= bound, "{name} at {chord}: {volume} vs {exact} (bound {bound})");
        }
    }
}

#[test]
fn the_flanged_hole_matches_pappus_and_is_refused_with_a_place_and_a_way_out() {
    // the cross-section revolved about the axis: plate, quarter annulus of the toroidal bend, collar
    let (t, r, collar, height, outer) = (1.5, 1.5, 5.0, 6.0, 25.0);
    let rho0: f64 = collar + t + r;
    let quarter = std::f64::consts::PI / 4.0 * ((r + t) * (r + t) - r * r);
    let offset = 4.0 * ((r + t).powi(3) - r.powi(3)) / (3.0 * std::f64::consts::PI * ((r + t).powi(2) - r * r));
    let sections = [
        ((outer - rho0) * t, 0.5 * (outer + rho0)),
        (quarter, rho0 - offset),
        (t * (height - t - r), collar + t / 2.0),
    ];
    let pappus: f64 = sections.iter().map(|(a, rho)| std::f64::consts::TAU * a * rho).sum();
    let f = facts("flanged_hole");
    assert!((pappus - num(&f, "volume")).abs() <= 1e-6 * pappus, "{pappus} vs {}", num(&f, "volume"));
    let brep = read_step(path("flanged_hole"), &StepOptions::default()).expect("reads");
    let volume = brep.volume.expect("volume");
    assert!((volume - pappus).abs() <= DEFAULT_CHORD_TOLERANCE * num(&f, "area"), "{volume} vs {pappus}");
    assert_eq!(brep.tessellation.map(|t| t.curved_faces), Some(2), "the two tori");
    let e = read_sheet(path("flanged_hole"), &ReadOptions::default()).expect_err("no plates and straight bends");
    let text = e.to_string();
    assert!(matches!(e, IoError::NotSheetMetal { .. }), "{text}");
    assert!(text.contains("flanged_hole.step") && text.contains("entity #"), "{text}");
    assert!(text.contains("--decompose"), "{text}");
}

/// Whether `p` is in the countersunk plate (as `make_fixtures.py` builds it).
fn in_countersink_plate(p: DVec3) -> bool {
    let t = 3.0;
    if !(0.0..=80.0).contains(&p.x) || !(0.0..=50.0).contains(&p.y) || !(0.0..=t).contains(&p.z) {
        return false;
    }
    let rho = |x: f64, y: f64| (p.x - x).hypot(p.y - y);
    // hole radius at height z: the through hole, widened by the 90 degree countersink
    let top = 2.75f64.max(2.75 + (p.z - (t - 2.75)));
    let bottom = 2.25f64.max(2.25 + (2.25 - p.z));
    rho(20.0, 25.0) >= top && rho(42.0, 25.0) >= bottom && rho(64.0, 25.0) >= 3.0
}

/// Whether `p` is in the NURBS flange (an L profile in x-z extruded along y, flange corners rounded).
fn in_flange(p: DVec3) -> bool {
    let (t, r, a, b, w, corner) = (2.0, 2.0, 40.0, 30.0, 40.0, 6.0);
    if !(0.0..=w).contains(&p.y) {
        return false;
    }
    let plate = (-a..=0.0).contains(&p.x) && (0.0..=t).contains(&p.z);
    let (dx, dz) = (p.x, p.z - (t + r));
    let bend = dx >= 0.0 && dz <= 0.0 && (r..=r + t).contains(&dx.hypot(dz));
    let top = t + r + b;
    let mut flange = (r..=r + t).contains(&p.x) && (t + r..=top).contains(&p.z);
    for cy in [corner, w - corner] {
        let beyond = if cy < w / 2.0 { p.y < cy } else { p.y > cy };
        if beyond && p.z > top - corner && (p.y - cy).hypot(p.z - (top - corner)) > corner {
            flange = false;
        }
    }
    plate || bend || flange
}

fn in_pieces(part: &Part, p: DVec3, tol: f64) -> bool {
    part.components().iter().any(|c| c.planes().all(|pl| pl.signed_distance(p) <= tol))
}

#[test]
fn points_of_the_exact_solids_lie_in_the_pieces_within_the_chord_tolerance() {
    type Inside = fn(DVec3) -> bool;
    let cases: [(&str, Inside, DVec3, DVec3); 2] = [
        ("countersink_plate", in_countersink_plate, DVec3::ZERO, DVec3::new(80.0, 50.0, 3.0)),
        ("flange_nurbs", in_flange, DVec3::new(-40.0, 0.0, 0.0), DVec3::new(4.0, 40.0, 34.0)),
    ];
    for (name, inside, lo, hi) in cases {
        let (part, r) = sheet(name);
        let chord = r.tessellation.expect("tessellated").chord_tolerance;
        let (mut count, n) = (0, 48);
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let s = DVec3::new(i as f64 + 0.37, j as f64 + 0.41, k as f64 + 0.29) / n as f64;
                    let p = lo + (hi - lo) * s;
                    if inside(p) {
                        count += 1;
                        assert!(in_pieces(&part, p, chord + 1e-9), "{name}: {p} outside the pieces");
                    }
                }
            }
        }
        assert!(count > 1000, "{name}: {count} points");
        // and points around the countersinks, where the hole's narrowest section decides
        if name == "countersink_plate" {
            for k in 0..720 {
                let a = k as f64 * std::f64::consts::TAU / 720.0;
                for (x, rho, z) in [(20.0, 2.8, 0.1), (20.0, 5.5, 2.95), (42.0, 2.3, 2.9), (42.0, 4.5, 0.05)] {
                    let p = DVec3::new(x + rho * a.cos(), 25.0 + rho * a.sin(), z);
                    assert!(inside(p), "{p}");
                    assert!(in_pieces(&part, p, chord + 1e-9), "{name}: {p} outside the pieces");
                }
            }
        }
    }
}

fn text(name: &str) -> String {
    std::fs::read_to_string(path(name)).expect("fixture")
}

#[test]
fn damaged_surfaces_and_curves_give_errors_that_name_the_entity() {
    // a rational B-spline surface with a multiplicity that no longer matches its poles
    let nurbs = text("flange_nurbs");
    let bad = nurbs.replacen("B_SPLINE_SURFACE_WITH_KNOTS((3,3),(2,2),", "B_SPLINE_SURFACE_WITH_KNOTS((3,2),(2,2),", 1);
    assert_ne!(bad, nurbs);
    let e = parse_step(bad.as_bytes(), Path::new("bad.step"), &StepOptions::default()).expect_err("bad knots");
    let msg = e.to_string();
    assert!(matches!(e, IoError::Syntax { at: Place::Entity(_), .. }), "{msg}");
    assert!(msg.contains("bad.step") && msg.contains("knots") && msg.contains("entity #"), "{msg}");
    // a weight of zero
    let bad = nurbs.replacen("(1.,1.)", "(0.,1.)", 1);
    let e = parse_step(bad.as_bytes(), Path::new("bad.step"), &StepOptions::default()).expect_err("zero weight");
    assert!(e.to_string().contains("weights"), "{e}");
    // a cone whose radius no longer meets its edges: the face's boundary is off its surface
    let cone = text("countersink_plate");
    let bad = cone.clone();
    let at = bad.find("CONICAL_SURFACE('',#").expect("a cone");
    let line_end = at + bad[at..].find(';').expect("end");
    let entity = &bad[at..line_end];
    let moved = entity.replacen(",2.75,", ",3.75,", 1);
    assert_ne!(moved, entity);
    let bad = format!("{}{}{}", &bad[..at], moved, &bad[line_end..]);
    let e = parse_step(bad.as_bytes(), Path::new("cone.step"), &StepOptions::default()).expect_err("off the cone");
    let msg = e.to_string();
    assert!(matches!(e, IoError::Tessellation { at: Place::Entity(_), .. }), "{msg}");
    assert!(msg.contains("off its surface #"), "{msg}");
    // a degree-2 curve whose knots are not increasing
    let bad = nurbs.replacen("(3.14159265359,4.712388980385)", "(4.712388980385,3.14159265359)", 1);
    assert_ne!(bad, nurbs);
    let e = parse_step(bad.as_bytes(), Path::new("bad.step"), &StepOptions::default()).expect_err("knot order");
    assert!(e.to_string().contains("strictly increasing"), "{e}");
    // a surface the reader does not know: still named
    let bad = cone.replacen("CONICAL_SURFACE('',#", "DEGENERATE_TOROIDAL_SURFACE('',#", 1);
    let e = parse_step(bad.as_bytes(), Path::new("cone.step"), &StepOptions::default()).expect_err("unknown");
    assert!(
        matches!(&e, IoError::Unsupported { kind, role: "faces", .. } if kind == "DEGENERATE_TOROIDAL_SURFACE"),
        "{e}"
    );
}

/// A conical ring as Parasolid writes periodic faces: a full cone and a full cylinder each between two circles,
/// without seam edges. Bottom annulus r 5..10 at z = 0, top annulus r 5..12 at z = 2, a 45 degree cone outside.
const SEAMLESS_RING: &str = "ISO-10303-21;
HEADER;
FILE_DESCRIPTION((''),'2;1');
FILE_NAME('ring','',(''),(''),'','','');
FILE_SCHEMA(('AUTOMOTIVE_DESIGN'));
ENDSEC;
DATA;
#1=CARTESIAN_POINT('',(0.,0.,0.));
#2=DIRECTION('',(0.,0.,1.));
#3=DIRECTION('',(1.,0.,0.));
#4=AXIS2_PLACEMENT_3D('',#1,#2,#3);
#5=CARTESIAN_POINT('',(0.,0.,2.));
#6=AXIS2_PLACEMENT_3D('',#5,#2,#3);
#10=CIRCLE('',#4,10.);
#11=CIRCLE('',#4,5.);
#12=CIRCLE('',#6,12.);
#13=CIRCLE('',#6,5.);
#20=CARTESIAN_POINT('',(10.,0.,0.));
#21=CARTESIAN_POINT('',(5.,0.,0.));
#22=CARTESIAN_POINT('',(12.,0.,2.));
#23=CARTESIAN_POINT('',(5.,0.,2.));
#30=VERTEX_POINT('',#20);
#31=VERTEX_POINT('',#21);
#32=VERTEX_POINT('',#22);
#33=VERTEX_POINT('',#23);
#40=EDGE_CURVE('',#30,#30,#10,.T.);
#41=EDGE_CURVE('',#31,#31,#11,.T.);
#42=EDGE_CURVE('',#32,#32,#12,.T.);
#43=EDGE_CURVE('',#33,#33,#13,.T.);
#50=ORIENTED_EDGE('',*,*,#40,.T.);
#51=ORIENTED_EDGE('',*,*,#40,.F.);
#52=ORIENTED_EDGE('',*,*,#41,.T.);
#53=ORIENTED_EDGE('',*,*,#41,.F.);
#54=ORIENTED_EDGE('',*,*,#42,.T.);
#55=ORIENTED_EDGE('',*,*,#42,.F.);
#56=ORIENTED_EDGE('',*,*,#43,.T.);
#57=ORIENTED_EDGE('',*,*,#43,.F.);
#60=EDGE_LOOP('',(#51));
#61=EDGE_LOOP('',(#52));
#62=EDGE_LOOP('',(#54));
#63=EDGE_LOOP('',(#57));
#64=EDGE_LOOP('',(#50));
#65=EDGE_LOOP('',(#55));
#66=EDGE_LOOP('',(#53));
#67=EDGE_LOOP('',(#56));
#70=FACE_OUTER_BOUND('',#60,.T.);
#71=FACE_BOUND('',#61,.T.);
#72=FACE_OUTER_BOUND('',#62,.T.);
#73=FACE_BOUND('',#63,.T.);
#74=FACE_BOUND('',#64,.T.);
#75=FACE_BOUND('',#65,.T.);
#76=FACE_BOUND('',#66,.T.);
#77=FACE_BOUND('',#67,.T.);
#80=PLANE('',#4);
#81=PLANE('',#6);
#82=CONICAL_SURFACE('',#4,10.,0.785398163397448);
#83=CYLINDRICAL_SURFACE('',#4,5.);
#90=ADVANCED_FACE('',(#70,#71),#80,.F.);
#91=ADVANCED_FACE('',(#72,#73),#81,.T.);
#92=ADVANCED_FACE('',(#74,#75),#82,.T.);
#93=ADVANCED_FACE('',(#76,#77),#83,.F.);
#100=CLOSED_SHELL('',(#90,#91,#92,#93));
#101=MANIFOLD_SOLID_BREP('',#100);
ENDSEC;
END-ISO-10303-21;
";

#[test]
fn full_cones_and_cylinders_without_seam_edges_are_cut_along_a_seam_of_their_own() {
    let exact = std::f64::consts::PI * (2.0 / 3.0 * (100.0 + 120.0 + 144.0) - 25.0 * 2.0);
    // surface area: two annuli, the cone's lateral area (slant 2 sqrt 2) and the cylinder's
    let area = std::f64::consts::PI
        * ((100.0 - 25.0) + (144.0 - 25.0) + (10.0 + 12.0) * 2.0 * std::f64::consts::SQRT_2 + 10.0 * 2.0);
    for chord in [DEFAULT_CHORD_TOLERANCE, 0.002] {
        let options = StepOptions { chord_tolerance: Some(chord), ..StepOptions::default() };
        let brep = parse_step(SEAMLESS_RING.as_bytes(), Path::new("ring.step"), &options).expect("reads");
        let t = brep.tessellation.expect("tessellated");
        assert_eq!((t.faces, t.curved_faces), (4, 1));
        let volume = brep.volume.expect("volume");
        assert!((volume - exact).abs() <= chord * area, "{volume} vs {exact}");
    }
}

#[test]
fn cut_and_mutated_cad_files_never_panic() {
    use stackplan_geom::cad::recognise::{RecogniseOptions, recognise};
    let file = Path::new("fuzz.step");
    let check = |b: &[u8]| match parse_step(b, file, &StepOptions::default()) {
        Ok(brep) => {
            // recognition of whatever was read returns too
            let _ = recognise(&brep, "fuzz", &RecogniseOptions::default());
        }
        Err(e) => assert!(e.to_string().contains("fuzz.step"), "{e}"),
    };
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for name in ["countersink_plate", "flange_nurbs", "spline_plate", "flanged_hole"] {
        let bytes = std::fs::read(path(name)).expect("fixture");
        for k in 1..40 {
            check(&bytes[..bytes.len() * k / 40]);
        }
        // digits changed in the data section: the same entities with other geometry (off-surface edges, crossing
        // loops, knots out of order, degenerate placements)
        let data = bytes.windows(5).position(|w| w == b"DATA;").unwrap_or(0);
        let digits: Vec<usize> = (data..bytes.len()).filter(|&i| bytes[i].is_ascii_digit()).collect();
        for _ in 0..60 {
            let mut m = bytes.clone();
            for _ in 0..1 + next() % 3 {
                let at = digits[(next() % digits.len() as u64) as usize];
                m[at] = b'0' + (next() % 10) as u8;
            }
            check(&m);
        }
    }
}
