//! The STEP reader on the six real BenDFM parts (`fixtures/realparts/`) and on small written boxes: face counts,
//! closed loops, planar loops on their planes and oriented about their normals, the enclosed volume against the
//! dataset's labels, bend radii and thickness, length units, and located errors on bad input.

use stackplan_geom::DVec3;
use stackplan_geom::cad::{Brep, BrepFace, FaceSource, Segment, Surface};
use stackplan_geom::io::step::{StepOptions, parse_step, read_step};
use stackplan_geom::io::{IoError, Place};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn realpart(n: usize, suffix: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../fixtures/realparts/bendfm_{n}{suffix}"))
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("readable")).expect("valid JSON")
}

fn read_real(n: usize) -> Brep {
    read_step(realpart(n, ".stp"), &StepOptions::default()).expect("a real part reads")
}

/// How many instances of `entity` the file defines (`#n = ENTITY(`).
fn count_entities(text: &str, entity: &str) -> usize {
    text.matches(&format!("= {entity}(")).count()
}

/// The largest coordinate magnitude of the B-rep's boundary: the scale of "relative" tolerances.
fn extent(brep: &Brep) -> f64 {
    brep.faces.iter().flat_map(|f| f.boundary_points(0.1)).map(|p| p.abs().max_element()).fold(1.0, f64::max)
}

/// The area enclosed by a loop about `normal`, from a fine polygon of its points (independent of the reader's exact
/// arc formula).
fn polygon_area(lp: &[Segment], normal: DVec3) -> f64 {
    let pts: Vec<DVec3> = lp
        .iter()
        .flat_map(|s| {
            let n = (s.sweep() / 1e-3).ceil().max(1.0) as usize;
            let p = s.points(n);
            p[..p.len() - 1].to_vec()
        })
        .collect();
    let o = pts.first().copied().unwrap_or(DVec3::ZERO);
    (0..pts.len()).map(|k| 0.5 * (pts[k] - o).cross(pts[(k + 1) % pts.len()] - o).dot(normal)).sum()
}

/// `integral over the face of p . n dA` (p about `origin`): a planar face's signed area times its plane's offset; a
/// cylindrical face's by Green's theorem in its unrolled (angle, height) chart, where only the lines along the axis
/// contribute (`F(theta) dh` with `F = r (c . w(theta) + r theta)`, `w' = u` the radial direction). The chart
/// argument needs the cylindrical face's loops oriented with the face on their left seen from outside.
fn flux(face: &BrepFace, origin: DVec3) -> f64 {
    match face.surface {
        Surface::Plane { point, normal } => {
            let area: f64 = face.loops.iter().map(|lp| polygon_area(lp, normal)).sum();
            (point - origin).dot(normal) * area
        }
        Surface::Cylinder { point, axis, radius, .. } => {
            let e1 = axis.any_orthonormal_vector();
            let e2 = axis.cross(e1);
            let c = point - origin;
            let angle = |p: DVec3| {
                let d = p - point;
                d.dot(e2).atan2(d.dot(e1))
            };
            let f = |theta: f64| {
                let w = e1 * theta.sin() - e2 * theta.cos();
                radius * (c.dot(w) + radius * theta)
            };
            let mut total = 0.0;
            for lp in &face.loops {
                let Some(first) = lp.first() else { continue };
                let mut theta = angle(first.start());
                for s in lp {
                    let dh = (s.end() - s.start()).dot(axis);
                    match *s {
                        Segment::Line { .. } => {
                            let mut turn = angle(s.end()) - angle(s.start());
                            turn -= (turn / (2.0 * PI)).round() * 2.0 * PI;
                            assert!(turn.abs() < 1e-9, "{}: a line across the cylinder's axis: {s:?}", face.source);
                            total += f(theta) * dh;
                            theta += turn;
                        }
                        Segment::Arc { axis: arc_axis, .. } => {
                            assert!(dh.abs() < 1e-9 * radius.max(1.0), "{}: arc not about the axis", face.source);
                            assert!(arc_axis.cross(axis).length() < 1e-9, "{}: arc not about the axis", face.source);
                            theta += s.sweep() * arc_axis.dot(axis).signum();
                        }
                    }
                }
            }
            total
        }
    }
}

fn volume(brep: &Brep) -> f64 {
    let origin =
        brep.faces.first().and_then(|f| f.loops.first()).and_then(|l| l.first()).map_or(DVec3::ZERO, |s| s.start());
    brep.faces.iter().map(|f| flux(f, origin)).sum::<f64>() / 3.0
}

#[test]
fn real_parts_have_every_face_and_every_cylinder_of_the_file() {
    for n in 0..6 {
        let text = std::fs::read_to_string(realpart(n, ".stp")).expect("readable");
        let brep = read_real(n);
        assert_eq!(brep.faces.len(), count_entities(&text, "ADVANCED_FACE"), "bendfm_{n}");
        let cylinders = brep.faces.iter().filter(|f| matches!(f.surface, Surface::Cylinder { .. })).count();
        assert_eq!(cylinders, count_entities(&text, "CYLINDRICAL_SURFACE"), "bendfm_{n}");
        assert_eq!(brep.volume, None);
        for f in &brep.faces {
            let FaceSource::Step { entity } = f.source else { panic!("bendfm_{n}: {:?}", f.source) };
            assert!(text.contains(&format!("#{entity} = ADVANCED_FACE(")), "bendfm_{n}: {entity}");
        }
    }
}

#[test]
fn real_parts_loops_are_closed_and_planar_loops_lie_on_their_planes_outer_first() {
    for n in 0..6 {
        let brep = read_real(n);
        let tol = 1e-9 * extent(&brep);
        for face in &brep.faces {
            assert!(!face.loops.is_empty(), "bendfm_{n} {}", face.source);
            for lp in &face.loops {
                assert!(!lp.is_empty(), "bendfm_{n} {}", face.source);
                for (k, s) in lp.iter().enumerate() {
                    let next = lp[(k + 1) % lp.len()];
                    assert!(s.end().distance(next.start()) <= tol, "bendfm_{n} {}: open at segment {k}", face.source);
                }
            }
            if let Surface::Plane { point, normal } = face.surface {
                assert!((normal.length() - 1.0).abs() < 1e-12);
                for p in face.boundary_points(0.05) {
                    let off = (p - point).dot(normal);
                    assert!(off.abs() <= tol, "bendfm_{n} {}: point {p} is {off} mm off its plane", face.source);
                }
                for (k, lp) in face.loops.iter().enumerate() {
                    let area = polygon_area(lp, normal);
                    if k == 0 {
                        assert!(area > 0.0, "bendfm_{n} {}: outer loop area {area}", face.source);
                    } else {
                        assert!(area < 0.0, "bendfm_{n} {}: hole {k} area {area}", face.source);
                    }
                }
            }
        }
    }
}

#[test]
fn real_parts_enclose_the_labelled_volume() {
    for n in 0..6 {
        let brep = read_real(n);
        let label = json(&realpart(n, "_labels.json"))["part_volume_3d"].as_f64().expect("labelled volume") * 1000.0;
        let v = volume(&brep);
        assert!(((v - label) / label).abs() < 1e-7, "bendfm_{n}: volume {v} mm^3, label {label}");
    }
}

#[test]
fn real_parts_bends_are_coaxial_cylinder_pairs_of_the_labelled_radius_and_thickness() {
    for n in 0..6 {
        let brep = read_real(n);
        let thickness = json(&realpart(n, "_labels.json"))["sheet_thickness"].as_f64().expect("thickness");
        let cylinders: Vec<(DVec3, DVec3, f64, bool)> = brep
            .faces
            .iter()
            .filter_map(|f| match f.surface {
                Surface::Cylinder { point, axis, radius, convex } => Some((point, axis, radius, convex)),
                Surface::Plane { .. } => None,
            })
            .collect();
        let coaxial = |a: &(DVec3, DVec3, f64, bool), b: &(DVec3, DVec3, f64, bool)| {
            a.1.cross(b.1).length() < 1e-9 && (b.0 - a.0).cross(a.1).length() < 1e-6
        };
        // Every inner (concave) bend surface has a coaxial outer (convex) one a thickness further out.
        let mut inner_radii = Vec::new();
        for c in cylinders.iter().filter(|c| !c.3) {
            let outer = cylinders
                .iter()
                .filter(|o| o.3 && coaxial(c, o))
                .any(|o| ((o.2 - c.2 - thickness) / thickness).abs() < 1e-6);
            assert!(outer, "bendfm_{n}: no outer surface for the inner radius {}", c.2);
            inner_radii.push(c.2);
        }
        let sequence = json(&realpart(n, "_sequence.json"));
        let bends = sequence.as_array().expect("a list").iter().filter_map(|b| b.get("bend_radius")?.as_f64());
        let mut count = 0;
        for r in bends {
            count += 1;
            assert!(inner_radii.iter().any(|&ri| (ri - r).abs() < 1e-6), "bendfm_{n}: bend radius {r} not found");
        }
        let labels = json(&realpart(n, "_labels.json"));
        assert_eq!(Some(count as u64), labels["total_bends"].as_u64(), "bendfm_{n}");
    }
}

/// A box `size` (mm) at `corner` (mm) written as a STEP file in a length unit of `mm_per_unit` mm, with the unit
/// entities `units` (instance numbers from 9001 on; the length unit must be `#9001`). Variants: one face on a plane
/// whose axis points inwards (`same_sense` .F.), one face's bound flagged reversed, one edge a degree-1
/// B-spline and one a polyline, both through an extra point, all inside `SURFACE_CURVE`s.
fn box_step(corner: DVec3, size: DVec3, mm_per_unit: f64, units: &str) -> String {
    let mut data = String::new();
    let mut next = 1u64;
    let mut add = |body: String| {
        let id = next;
        next += 1;
        writeln!(data, "#{id} = {body};").expect("write to String");
        id
    };
    let num = |x: f64| format!("{:?}", x / mm_per_unit);
    let point = |add: &mut dyn FnMut(String) -> u64, p: DVec3| {
        add(format!("CARTESIAN_POINT('',({},{},{}))", num(p.x), num(p.y), num(p.z)))
    };
    let corner_point =
        |i: usize| corner + size * DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
    let vertices: Vec<u64> = (0..8)
        .map(|i| {
            let p = point(&mut add, corner_point(i));
            add(format!("VERTEX_POINT('',#{p})"))
        })
        .collect();
    let mut edges: HashMap<(usize, usize), u64> = HashMap::new();
    let mut edge_kind = 0;
    let mut faces = Vec::new();
    for k in 0..3 {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        for side in 0..2 {
            let bit = |x: usize, y: usize| (side << k) | (x << a) | (y << b);
            let mut ring = [bit(0, 0), bit(1, 0), bit(1, 1), bit(0, 1)];
            if side == 0 {
                ring.reverse();
            }
            let mut oriented = Vec::new();
            for j in 0..4 {
                let (from, to) = (ring[j], ring[(j + 1) % 4]);
                let key = (from.min(to), from.max(to));
                let edge = match edges.get(&key) {
                    Some(&e) => e,
                    None => {
                        let (p, q) = (corner_point(key.0), corner_point(key.1));
                        let curve = match edge_kind {
                            0 => {
                                let mid = point(&mut add, (p + q) / 2.0);
                                let cps = [point(&mut add, p), mid, point(&mut add, q)];
                                add(format!(
                                    "B_SPLINE_CURVE_WITH_KNOTS('',1,(#{},#{},#{}),.POLYLINE_FORM.,.F.,.F.,(2,1,2),(0.,1.,2.),.UNSPECIFIED.)",
                                    cps[0], cps[1], cps[2]
                                ))
                            }
                            1 => {
                                let pts =
                                    [point(&mut add, p), point(&mut add, (p * 3.0 + q) / 4.0), point(&mut add, q)];
                                add(format!("POLYLINE('',(#{},#{},#{}))", pts[0], pts[1], pts[2]))
                            }
                            _ => {
                                let o = point(&mut add, p);
                                let d = (q - p).normalize();
                                let dir = add(format!("DIRECTION('',({:?},{:?},{:?}))", d.x, d.y, d.z));
                                let v = add(format!("VECTOR('',#{dir},1.)"));
                                add(format!("LINE('',#{o},#{v})"))
                            }
                        };
                        edge_kind += 1;
                        let curve = add(format!("SURFACE_CURVE('',#{curve},(),.CURVE_3D.)"));
                        let e = add(format!("EDGE_CURVE('',#{},#{},#{curve},.T.)", vertices[key.0], vertices[key.1]));
                        edges.insert(key, e);
                        e
                    }
                };
                let sense = if from == key.0 { ".T." } else { ".F." };
                oriented.push(add(format!("ORIENTED_EDGE('',*,*,#{edge},{sense})")));
            }
            let list = oriented.iter().map(|o| format!("#{o}")).collect::<Vec<_>>().join(",");
            let edge_loop = add(format!("EDGE_LOOP('',({list}))"));
            // The box's second face has its bound (and its loop) written reversed: the reader orients planar loops
            // from the geometry.
            let (bound, loop_sense) =
                if faces.len() == 1 { ("FACE_BOUND", ".F.") } else { ("FACE_OUTER_BOUND", ".T.") };
            let bound = add(format!("{bound}('',#{edge_loop},{loop_sense})"));
            let mut normal = DVec3::ZERO;
            normal[k] = if side == 1 { 1.0 } else { -1.0 };
            // The third face's plane axis points into the box, with the face's same_sense .F.
            let (axis, same_sense) = if faces.len() == 2 { (-normal, ".F.") } else { (normal, ".T.") };
            let o = point(&mut add, corner_point(ring[0]));
            let z = add(format!("DIRECTION('',({:?},{:?},{:?}))", axis.x, axis.y, axis.z));
            let placement = add(format!("AXIS2_PLACEMENT_3D('',#{o},#{z},$)"));
            let plane = add(format!("PLANE('',#{placement})"));
            faces.push(add(format!("ADVANCED_FACE('',(#{bound}),#{plane},{same_sense})")));
        }
    }
    let list = faces.iter().map(|o| format!("#{o}")).collect::<Vec<_>>().join(",");
    let shell = add(format!("CLOSED_SHELL('',({list}))"));
    let solid = add(format!("MANIFOLD_SOLID_BREP('box',#{shell})"));
    add(format!("ADVANCED_BREP_SHAPE_REPRESENTATION('',(#{solid}),#9000)"));
    add("PRODUCT('box','box','',())".to_string());
    format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('a box'),'2;1');\nFILE_NAME('box.stp','',(''),(''),'','','');\n\
         FILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n{data}\
         #9000 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((#9001,#9099)) \
         REPRESENTATION_CONTEXT('','') );\n{units}\n\
         #9099 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );\nENDSEC;\nEND-ISO-10303-21;\n"
    )
}

const MM: &str = "#9001 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );";
const METRE: &str = "#9001 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT($,.METRE.) );";
const INCH: &str = "#9001 = ( CONVERSION_BASED_UNIT('INCH',#9002) LENGTH_UNIT() NAMED_UNIT(#9004) );\n\
    #9002 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#9003);\n\
    #9003 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n\
    #9004 = DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.);";
const FOOT: &str = "#9001 = ( CONVERSION_BASED_UNIT('FOOT',#9002) LENGTH_UNIT() NAMED_UNIT(*) );\n\
    #9002 = ( LENGTH_MEASURE_WITH_UNIT() MEASURE_WITH_UNIT(LENGTH_MEASURE(12.),#9003) );\n\
    #9003 = ( CONVERSION_BASED_UNIT('INCH',#9005) LENGTH_UNIT() NAMED_UNIT(*) );\n\
    #9005 = MEASURE_WITH_UNIT(LENGTH_MEASURE(2.54),#9006);\n\
    #9006 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.CENTI.,.METRE.) );";

const CORNER: DVec3 = DVec3::new(-12.7, 25.4, 304.8);
const SIZE: DVec3 = DVec3::new(25.4, 50.8, 12.7);

fn parse(text: &str, options: &StepOptions) -> Result<Brep, IoError> {
    parse_step(text.as_bytes(), Path::new("box.stp"), options)
}

#[test]
fn a_box_reads_to_the_same_millimetres_in_every_length_unit() {
    let mm = parse(&box_step(CORNER, SIZE, 1.0, MM), &StepOptions::default()).expect("mm");
    assert_eq!(mm.faces.len(), 6);
    assert!((volume(&mm) - SIZE.x * SIZE.y * SIZE.z).abs() < 1e-9 * SIZE.x * SIZE.y * SIZE.z);
    for face in &mm.faces {
        let Surface::Plane { point, normal } = face.surface else { panic!("{face:?}") };
        assert_eq!(face.loops.len(), 1);
        assert!(polygon_area(&face.loops[0], normal) > 0.0, "{}", face.source);
        // Outward: the box's centre is behind every face.
        assert!((CORNER + SIZE / 2.0 - point).dot(normal) < 0.0, "{}", face.source);
    }
    for (units, mm_per_unit) in [(METRE, 1000.0), (INCH, 25.4), (FOOT, 304.8)] {
        let other = parse(&box_step(CORNER, SIZE, mm_per_unit, units), &StepOptions::default()).expect("reads");
        assert_eq!(other.faces.len(), 6);
        for (a, b) in mm.faces.iter().zip(&other.faces) {
            assert_eq!(a.source, b.source);
            let (pa, pb) = (a.boundary_points(0.1), b.boundary_points(0.1));
            assert_eq!(pa.len(), pb.len());
            for (p, q) in pa.iter().zip(&pb) {
                assert!(p.distance(*q) < 1e-12 * 400.0, "{mm_per_unit}: {p} vs {q}");
            }
        }
    }
}

#[test]
fn cylinder_and_circle_radii_are_scaled_to_millimetres() {
    // The inch box's shell with one more face: a cylinder of radius 0.5 in about the z axis through (1, 2, 0) in,
    // bounded by a full circle (one vertex) at z = 0, written clockwise (.F.) about the circle's axis.
    let extra = "#8001 = CARTESIAN_POINT('',(1.,2.,0.));\n#8002 = DIRECTION('',(0.,0.,1.));\n\
        #8003 = DIRECTION('',(1.,0.,0.));\n#8004 = AXIS2_PLACEMENT_3D('',#8001,#8002,#8003);\n\
        #8005 = CYLINDRICAL_SURFACE('',#8004,0.5);\n#8006 = CIRCLE('',#8004,0.5);\n\
        #8007 = CARTESIAN_POINT('',(1.5,2.,0.));\n#8008 = VERTEX_POINT('',#8007);\n\
        #8009 = EDGE_CURVE('',#8008,#8008,#8006,.F.);\n#8010 = ORIENTED_EDGE('',*,*,#8009,.T.);\n\
        #8011 = EDGE_LOOP('',(#8010));\n#8012 = FACE_BOUND('',#8011,.T.);\n\
        #8013 = ADVANCED_FACE('',(#8012),#8005,.F.);\n";
    let text = box_step(CORNER, SIZE, 25.4, INCH);
    let shell = first_instance(&text, "CLOSED_SHELL");
    let text =
        text.replace(&format!("#{shell} = CLOSED_SHELL('',("), &format!("{extra}#{shell} = CLOSED_SHELL('',(#8013,"));
    let brep = parse(&text, &StepOptions::default()).expect("reads");
    assert_eq!(brep.faces.len(), 7);
    let face = &brep.faces[0];
    assert_eq!(face.source, FaceSource::Step { entity: 8013 });
    let Surface::Cylinder { point, axis, radius, convex } = face.surface else { panic!("{face:?}") };
    assert!(point.distance(DVec3::new(25.4, 50.8, 0.0)) < 1e-12 && axis == DVec3::Z && !convex);
    assert!((radius - 12.7).abs() < 1e-12, "{radius}");
    let [Segment::Arc { center, axis, radius, start, end }] = face.loops[0][..] else { panic!("{face:?}") };
    assert!(center.distance(point) < 1e-12 && axis == -DVec3::Z && (radius - 12.7).abs() < 1e-12);
    assert!(start == end && start.distance(DVec3::new(38.1, 50.8, 0.0)) < 1e-12);
}

#[test]
fn a_file_without_a_length_unit_is_read_in_millimetres() {
    let text = box_step(CORNER, SIZE, 1.0, "#9001 = DIMENSIONAL_EXPONENTS(0.,0.,0.,0.,0.,0.,0.);");
    let brep = parse(&text, &StepOptions::default()).expect("reads");
    assert!((volume(&brep) - SIZE.x * SIZE.y * SIZE.z).abs() < 1e-6);
}

fn expect_err(text: &str, options: &StepOptions) -> IoError {
    let e = parse(text, options).expect_err("must fail");
    assert_eq!(e.file(), Path::new("box.stp"));
    assert!(e.to_string().starts_with("box.stp: "), "{e}");
    e
}

/// The instance number of the first `entity` of the text.
fn first_instance(text: &str, entity: &str) -> u64 {
    let at = text.find(&format!(" = {entity}(")).expect("present");
    let start = text[..at].rfind('#').expect("instance");
    text[start + 1..at].parse().expect("number")
}

#[test]
fn a_surface_that_is_not_read_is_an_error_naming_the_entity_and_its_face() {
    let text = box_step(CORNER, SIZE, 1.0, MM);
    let plane = first_instance(&text, "PLANE");
    let placement = text.split(&format!("#{plane} = PLANE('',#")).nth(1).and_then(|r| r.split(')').next()).expect("x");
    let with = |surface: String| text.replace(&format!("#{plane} = PLANE('',#{placement});"), &surface);
    let offset = with(format!("#{plane} = OFFSET_SURFACE('',#{placement},5.,.F.);"));
    let e = expect_err(&offset, &StepOptions::default());
    let IoError::Unsupported { at: Place::Entity(at), kind, role, face: Some(_), .. } = &e else { panic!("{e:?}") };
    assert_eq!((*at, kind.as_str(), *role), (plane, "OFFSET_SURFACE", "faces"));
    assert!(e.to_string().contains(&format!("entity #{plane}: OFFSET_SURFACE faces are not supported")), "{e}");
    // a cone is read, and tessellated; this one does not pass through its face's edges, and the error says so
    let conical = with(format!("#{plane} = CONICAL_SURFACE('',#{placement},5.,0.5);"));
    let e = expect_err(&conical, &StepOptions::default());
    let IoError::Tessellation { at: Place::Entity(face), message, .. } = &e else { panic!("{e:?}") };
    assert!(text.contains(&format!("#{face} = ADVANCED_FACE(")), "{e}");
    assert!(message.contains(&format!("off its surface #{plane}")), "{e}");
}

#[test]
fn a_curve_that_is_not_read_or_not_consistent_is_an_error_naming_the_entity() {
    let text = box_step(CORNER, SIZE, 1.0, MM);
    let spline = first_instance(&text, "B_SPLINE_CURVE_WITH_KNOTS");
    // a degree-2 spline with the knots of a degree-1 one: inconsistent, named
    let quadratic = text.replace("B_SPLINE_CURVE_WITH_KNOTS('',1,", "B_SPLINE_CURVE_WITH_KNOTS('',2,");
    let e = expect_err(&quadratic, &StepOptions::default());
    let IoError::Syntax { at: Place::Entity(at), message, .. } = &e else { panic!("{e:?}") };
    assert_eq!(*at, spline);
    assert!(message.contains("knots") && message.contains("degree 2"), "{e}");
    // a curve the reader does not know
    let head = format!("#{spline} = B_SPLINE_CURVE_WITH_KNOTS(");
    let start = text.find(&head).expect("the spline");
    let end = start + text[start..].find(';').expect("its end");
    let hyperbola = format!("{}#{spline} = HYPERBOLA('',#1,1.,1.){}", &text[..start], &text[end..]);
    let e = expect_err(&hyperbola, &StepOptions::default());
    let IoError::Unsupported { at: Place::Entity(at), kind, role: "edges", .. } = &e else { panic!("{e:?}") };
    assert_eq!((*at, kind.as_str()), (spline, "HYPERBOLA"));
}

#[test]
fn a_missing_reference_is_an_error_naming_the_referrer() {
    let text = box_step(CORNER, SIZE, 1.0, MM);
    let vertex = first_instance(&text, "VERTEX_POINT");
    let head = format!("#{vertex} = VERTEX_POINT('',#");
    let point: String =
        text[text.find(&head).expect("the vertex") + head.len()..].chars().take_while(char::is_ascii_digit).collect();
    let broken = text.replacen(&format!("{head}{point})"), &format!("{head}999999)"), 1);
    let e = expect_err(&broken, &StepOptions::default());
    let IoError::MissingReference { at: Place::Entity(at), target: 999_999, .. } = &e else { panic!("{e:?}") };
    assert_eq!(*at, vertex);
    assert!(e.to_string().contains("refers to #999999"), "{e}");
}

#[test]
fn a_wrong_argument_is_an_error_naming_the_entity() {
    let text = box_step(CORNER, SIZE, 1.0, MM).replacen(".T.)", "1)", 1);
    let e = expect_err(&text, &StepOptions::default());
    assert!(matches!(e, IoError::Syntax { at: Place::Entity(_), .. }), "{e:?}");
    assert!(e.to_string().contains("must be .T. or .F."), "{e}");
}

#[test]
fn two_solids_need_a_choice() {
    let text = box_step(CORNER, SIZE, 1.0, MM);
    let solid = first_instance(&text, "MANIFOLD_SOLID_BREP");
    let shell = first_instance(&text, "CLOSED_SHELL");
    let two =
        text.replace("ENDSEC;\nEND-ISO", &format!("#8000 = MANIFOLD_SOLID_BREP('again',#{shell});\nENDSEC;\nEND-ISO"));
    let e = expect_err(&two, &StepOptions::default());
    assert!(matches!(e, IoError::SeveralSolids { count: 2, .. }), "{e:?}");
    assert!(e.to_string().contains("2 solids") && e.to_string().contains("--solid"), "{e}");
    for index in 0..2 {
        let brep =
            parse(&two, &StepOptions { solid: Some(index), ..Default::default() }).expect("a chosen solid reads");
        assert_eq!(brep.faces.len(), 6);
    }
    let e = expect_err(&two, &StepOptions { solid: Some(2), ..Default::default() });
    assert!(matches!(e, IoError::NoSuchSolid { index: 2, count: 2, .. }), "{e:?}");
    // A closed shell that no solid uses is a solid of its own.
    let bare = text.replace(&format!("#{solid} = MANIFOLD_SOLID_BREP('box',#{shell});"), "");
    assert_eq!(parse(&bare, &StepOptions::default()).expect("the shell reads").faces.len(), 6);
}

#[test]
fn a_solid_with_voids_is_an_error_naming_it() {
    let text = box_step(CORNER, SIZE, 1.0, MM);
    let shell = first_instance(&text, "CLOSED_SHELL");
    let solid = first_instance(&text, "MANIFOLD_SOLID_BREP");
    let voids =
        text.replace(&format!("MANIFOLD_SOLID_BREP('box',#{shell})"), &format!("BREP_WITH_VOIDS('box',#{shell},())"));
    let e = expect_err(&voids, &StepOptions::default());
    assert!(matches!(&e, IoError::Unsupported { at: Place::Entity(s), role: "solids", .. } if *s == solid), "{e:?}");
}

#[test]
fn a_truncated_real_file_is_a_syntax_error_with_its_line() {
    let bytes = std::fs::read(realpart(1, ".stp")).expect("readable");
    let text = String::from_utf8(bytes).expect("ASCII");
    let cut = text.find("#900 = ").expect("entity #900") + 24;
    let e = parse_step(&text.as_bytes()[..cut], Path::new("cut.stp"), &StepOptions::default()).expect_err("fails");
    let line = text[..cut].lines().count();
    let IoError::Syntax { at: Place::Line(l), message, .. } = &e else { panic!("{e:?}") };
    assert_eq!(*l, line, "{e}");
    assert!(message.contains("end of file"), "{e}");
    assert!(e.to_string().starts_with("cut.stp: line "), "{e}");
}

#[test]
fn empty_files_and_binary_garbage_are_located_errors() {
    for bytes in [&b""[..], b"  \n\r\n"] {
        let e = parse_step(bytes, Path::new("empty.stp"), &StepOptions::default()).expect_err("empty");
        assert!(matches!(e, IoError::Empty { at: Place::WholeFile, .. }), "{e:?}");
        assert!(e.to_string().starts_with("empty.stp: whole file: "), "{e}");
    }
    let garbage: Vec<u8> = (0..4096u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
    let e = parse_step(&garbage, Path::new("garbage.stp"), &StepOptions::default()).expect_err("garbage");
    assert!(matches!(e, IoError::Syntax { at: Place::Line(_), .. }), "{e:?}");
    let e = read_step("/nonexistent/part.stp", &StepOptions::default()).expect_err("no file");
    assert!(matches!(e, IoError::Os { .. }), "{e:?}");
}

#[test]
fn cut_and_mutated_real_files_never_panic() {
    let bytes = std::fs::read(realpart(1, ".stp")).expect("readable");
    let file = Path::new("fuzz.stp");
    let options = StepOptions::default();
    let check = |b: &[u8]| {
        if let Err(e) = parse_step(b, file, &options) {
            assert!(e.to_string().contains("fuzz.stp"), "{e}");
        }
    };
    for k in 0..200 {
        check(&bytes[..bytes.len() * k / 200]);
    }
    let replacements = [b'#', b'(', b')', b',', b';', b'\'', b'.', b'0', b'9', b'-', b'E', b'$', b'*', b'\n', 0xff];
    for k in 0..200 {
        let mut m = bytes.clone();
        let at = (bytes.len() - 1) * k / 199;
        m[at] = replacements[k % replacements.len()];
        check(&m);
    }
}
