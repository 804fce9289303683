//! Sheet-metal recognition: the thickness, plates and bends of a solid given by its planar and cylindrical faces
//! ([`Brep`]), and the conservative convex pieces of the part.
//!
//! A bent sheet of constant thickness `t` is bounded by
//! - **skins**: pairs of opposite planar faces `t` apart (outward normals opposite, the material between them), whose
//!   projections overlap. The two skins of a plate have the same outline, since a cut edge is square to the sheet;
//! - **bends**: pairs of coaxial cylinders, the inner (normal towards the axis) of radius `r` and the outer of radius
//!   `r + t`;
//! - **cut edges**: the narrow faces of width `t` around the sheet (rims, the walls of holes, the sides of bends).
//!
//! Recognition:
//! 1. Each planar face's **partner** is the nearest opposite face behind it whose projection overlaps its own. The
//!    thickness is the distance of the partner pair with the largest common area (the main plate); each bend's
//!    radii must differ by it, and a face whose partner is nearer or farther than it while it is not a cut edge makes
//!    the solid no sheet ("faces #12 and #40 are parallel but 7.1 mm apart; the sheet is 3.13 mm").
//! 2. **Plates**: the partner pairs at the thickness form groups (a side may be split into several faces); the side of
//!    larger area gives the plate's faces, whose loops, moved onto the mid-plane, are the outline and holes of a
//!    [`SheetFace`]. A circular arc of a loop becomes a polygon that never cuts into the material: where the
//!    material lies on the arc's centre side (a rounded corner) the polygon is made of tangents; where it lies on the
//!    far side (a hole, a notch) of chords. The plates are then split into convex prisms as every sheet-metal face is
//!    ([`SheetMetal::build_part`]: exact, holes included).
//! 3. **Bends**: cylinders of one axis and radius are merged; an inner and an outer cylinder on one axis with radii
//!    `t` apart whose angle ranges overlap make a bend ([`Bend`]), its angle and axial interval the range of both
//!    cylinders' boundary points. A tessellated bend (from a mesh) has chords inside its inner arc, so its inner
//!    radius for the pieces is the least distance of its boundary edges from the axis: the pieces contain the mesh,
//!    not only the true cylinder. Each bend becomes [`Bend::segments`] within the bend tolerance.
//! 4. **Check**: every boundary point of the solid (arcs sampled every 5 degrees) must lie in the union of the pieces
//!    within the length tolerance; the first that does not names its face and how far outside it is.
//!
//! The solid's volume is the source's when it knows it (the enclosed volume of a mesh); for a B-rep it is the exact
//! volume of the recognised sheet (each plate's area with its true arcs times the thickness, plus the bends' annular
//! sectors), which the check above ties to the faces.
//!
//! Cost: O(F^2) face pairs for the partners (F faces, with cheap normal and box rejections first) plus one point in
//! polygon test per sample; O(P x C) for the check (P boundary points, C pieces, with box rejection); the plates'
//! decomposition as in [`crate::sheet_metal`].

use super::bend::Bend;
use super::{Brep, BrepFace, FaceSource, Segment, Surface, loop_area};
use crate::part::{Part, PartError, PartOrigin};
use crate::plate::Plate;
use crate::polygon::{PointInRing, point_in_ring};
use crate::polytope::{ConvexPolytope, PolytopeError};
use crate::sheet_metal::{Decomposition, SheetFace, SheetMetal, SheetMetalError};
use crate::union_find::{find, union};
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// The default bend tolerance (mm): how far a piece may stand outside the solid at a bend or a rounded outline.
/// 0.1 mm keeps the pieces' volume within a few hundredths of a percent of the solid's for the bends of common
/// sheets (radius up to ten times the thickness), with 5-7 segments for a 90 degree bend of radius 3-14 mm.
pub const DEFAULT_BEND_TOLERANCE: f64 = 0.1;

/// Options of the recognition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecogniseOptions {
    /// The largest distance (mm, > 0) by which a piece may stand outside the solid at a bend or an arc of an outline.
    pub bend_tolerance: f64,
    /// How plates with holes or concave outlines are split into convex polygons.
    pub decomposition: Decomposition,
    /// The length tolerance (mm) of the geometric tests: opposite faces one thickness apart, coaxial cylinders, the
    /// containment check. The caller sets it from the source's precision (a mesh's single-precision coordinates).
    pub tolerance: f64,
    /// The part's density.
    pub density: f64,
}

impl Default for RecogniseOptions {
    fn default() -> Self {
        Self {
            bend_tolerance: DEFAULT_BEND_TOLERANCE,
            decomposition: Decomposition::default(),
            tolerance: 1e-6,
            density: 1.0,
        }
    }
}

/// A recognised plate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecognisedPlate {
    /// The faces of the side that gives the outline.
    pub faces: Vec<FaceSource>,
    /// The faces of the other side.
    pub other_side: Vec<FaceSource>,
    /// Unit normal of the mid-plane (the outward normal of `faces`).
    pub normal: DVec3,
    /// Area of the mid-surface (mm^2), exact (arcs as arcs).
    pub area: f64,
    /// Number of holes.
    pub holes: usize,
    /// Number of circular arcs in the outline and holes.
    pub arcs: usize,
    /// The part's components that make the plate (indices into [`Part::components`]).
    pub pieces: Vec<usize>,
}

/// A recognised bend.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecognisedBend {
    /// The geometry: axis, radii, angle, axial interval. `inner_radius` is the fitted or exact radius of the inner
    /// cylinder.
    pub bend: Bend,
    /// The inner cylinder's faces.
    pub inner_faces: Vec<FaceSource>,
    /// The outer cylinder's faces.
    pub outer_faces: Vec<FaceSource>,
    /// The part's components that make the bend (indices into [`Part::components`]).
    pub pieces: Vec<usize>,
}

/// What was recognised in a solid: the sheet, its plates and bends, and how the pieces compare with the solid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recognition {
    /// The sheet thickness (mm).
    pub thickness: f64,
    /// The plates.
    pub plates: Vec<RecognisedPlate>,
    /// The bends.
    pub bends: Vec<RecognisedBend>,
    /// The solid's volume (mm^3): see the module documentation.
    pub solid_volume: f64,
    /// The pieces' volume (mm^3), at least the solid's.
    pub pieces_volume: f64,
    /// The largest distance by which a piece stands outside the solid (mm), by construction.
    pub max_deviation: f64,
    /// The bend tolerance the pieces were made with (mm).
    pub bend_tolerance: f64,
    /// For a STEP solid with faces on other surfaces than planes and cylinders: how it was tessellated. The pieces
    /// are then recognised from the mesh: they contain it, and the solid to within the chord tolerance; they stand
    /// outside the solid by at most `max_deviation`, which includes the chord tolerance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tessellation: Option<super::Tessellation>,
}

/// Why a solid is not recognised as sheet metal. Every message names the faces.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RecogniseError {
    /// No pair of opposite planar faces with the material between them.
    #[error(
        "no two opposite planar faces enclose material: this is no sheet (--decompose reads any solid approximately)"
    )]
    NoPlates,
    /// A bend's radii do not differ by the thickness.
    #[error(
        "the bend of {inner} (radius {inner_radius:.4} mm) and {outer} (radius {outer_radius:.4} mm) is {bend:.4} mm \
         thick, but the sheet is {thickness:.4} mm (--decompose reads any solid approximately)"
    )]
    BendThickness {
        /// Inner cylinder face.
        inner: FaceSource,
        /// Outer cylinder face.
        outer: FaceSource,
        /// Inner radius (mm).
        inner_radius: f64,
        /// Outer radius (mm).
        outer_radius: f64,
        /// Their difference (mm).
        bend: f64,
        /// The sheet's thickness (mm).
        thickness: f64,
    },
    /// Two opposite faces are not one thickness apart, and the solid is not covered by the recognised sheet there.
    #[error(
        "{a} and {b} are parallel but {distance:.4} mm apart; the sheet is {thickness:.4} mm: this is no sheet of \
         constant thickness (--decompose reads any solid approximately)"
    )]
    NotConstantThickness {
        /// One face.
        a: FaceSource,
        /// The other.
        b: FaceSource,
        /// Their distance (mm).
        distance: f64,
        /// The sheet's thickness (mm).
        thickness: f64,
    },
    /// A point of the solid's boundary lies outside every piece.
    #[error(
        "{face} reaches ({:.4}, {:.4}, {:.4}), {distance:.4} mm outside every recognised plate and bend of the \
         {thickness:.4} mm sheet (--decompose reads any solid approximately)",
        point.x, point.y, point.z
    )]
    Outside {
        /// The face.
        face: FaceSource,
        /// The point.
        point: DVec3,
        /// Its distance outside the nearest piece (mm, a lower bound).
        distance: f64,
        /// The sheet's thickness (mm).
        thickness: f64,
    },
    /// Pieces of two plates (or of a plate and a bend) overlap: the faces pair up, but not as one sheet.
    #[error(
        "the pieces recognised from {a} and from {b} overlap: this is no sheet of constant thickness \
         (--decompose reads any solid approximately)"
    )]
    Overlap {
        /// A face of the first plate or bend.
        a: FaceSource,
        /// A face of the second.
        b: FaceSource,
    },
    /// The plates do not make a valid sheet-metal model (a self-intersecting outline, a hole touching the outline).
    #[error("the plate of {face}: {source}")]
    Plate {
        /// The plate's (first) face.
        face: FaceSource,
        /// The model's reason.
        source: SheetMetalError,
    },
    /// A bend's segments are not valid polytopes (a bend thinner than the kernel's tolerance).
    #[error("the bend of {inner}: {source}")]
    Bend {
        /// The inner cylinder's face.
        inner: FaceSource,
        /// The reason.
        source: PolytopeError,
    },
    /// The pieces do not make a part.
    #[error(transparent)]
    Part(#[from] PartError),
    /// A bad option.
    #[error("the bend tolerance must be positive and finite, got {0}")]
    BadTolerance(f64),
    /// A tessellated solid whose chord tolerance leaves nothing of the bend tolerance for the pieces.
    #[error(
        "the bend tolerance ({bend_tolerance} mm) must exceed the chord tolerance of the tessellation ({chord} mm)"
    )]
    ChordTolerance {
        /// The chord tolerance (mm).
        chord: f64,
        /// The bend tolerance (mm).
        bend_tolerance: f64,
    },
}

/// One planar face, prepared: its frame and its loops as 2-D polygons (arcs sampled) for overlap tests.
struct PlanarFace<'a> {
    face: &'a BrepFace,
    point: DVec3,
    normal: DVec3,
    u: DVec3,
    v: DVec3,
    /// Loops in the face's frame (outer first).
    rings: Vec<Vec<DVec2>>,
    /// Exact area (arcs as arcs), mm^2.
    area: f64,
    lo: DVec3,
    hi: DVec3,
}

/// Cylinders of one axis line, radius and side.
struct Cylinder {
    point: DVec3,
    axis: DVec3,
    radius: f64,
    convex: bool,
    faces: Vec<usize>,
    points: Vec<DVec3>,
}

/// Sampling step on arcs for tests (radians): 5 degrees.
const ARC_STEP: f64 = std::f64::consts::PI / 36.0;

/// Recognises `brep` as sheet metal and builds its conservative part. See the module documentation.
pub fn recognise(brep: &Brep, name: &str, options: &RecogniseOptions) -> Result<(Part, Recognition), RecogniseError> {
    if !(options.bend_tolerance > 0.0 && options.bend_tolerance.is_finite()) {
        return Err(RecogniseError::BadTolerance(options.bend_tolerance));
    }
    // a tessellated solid: the mesh stands up to its chord tolerance outside the solid, so the pieces get the rest
    let chord = brep.tessellation.map_or(0.0, |t| t.chord_tolerance);
    let bend_tolerance = options.bend_tolerance - chord;
    if bend_tolerance.is_nan() || bend_tolerance <= 0.0 {
        return Err(RecogniseError::ChordTolerance { chord, bend_tolerance: options.bend_tolerance });
    }
    let tol = options.tolerance.max(1e-12);
    let planes: Vec<PlanarFace<'_>> = brep
        .faces
        .iter()
        .filter_map(|face| match face.surface {
            Surface::Plane { point, normal } => planar_face(face, point, normal),
            Surface::Cylinder { .. } => None,
        })
        .collect();
    // 1. partners and thickness
    let partners: Vec<Option<(usize, f64)>> = (0..planes.len()).map(|i| partner(&planes, i, tol)).collect();
    let thickness = partners
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.map(|(j, d)| (planes[i].area.min(planes[j].area), d)))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, d)| d)
        .ok_or(RecogniseError::NoPlates)?;
    let sheet_tol = tol.max(thickness * 1e-6);
    let at_thickness = |d: f64| (d - thickness).abs() <= 2.0 * sheet_tol;
    // 2. plates: groups of partner pairs at the thickness
    let mut parent: Vec<usize> = (0..planes.len()).collect();
    for (i, p) in partners.iter().enumerate() {
        if let Some((j, d)) = *p
            && at_thickness(d)
        {
            union(&mut parent, i, j);
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = std::collections::BTreeMap::new();
    for i in 0..planes.len() {
        let paired = partners[i].is_some_and(|(_, d)| at_thickness(d))
            || partners.iter().any(|p| p.is_some_and(|(j, d)| j == i && at_thickness(d)));
        if paired {
            let root = find(&mut parent, i);
            groups.entry(root).or_default().push(i);
        }
    }
    let mut sheet = SheetMetal { thickness, faces: Vec::new() };
    let mut plate_records: Vec<RecognisedPlate> = Vec::new();
    // each plate's mid-plane: (unit normal, a point)
    let mut mid_planes: Vec<(DVec3, DVec3)> = Vec::new();
    let mut max_deviation: f64 = 0.0;
    let mut exact_volume = 0.0;
    for members in groups.values() {
        // the two sides: by the sign of the normal against the first member's
        let n0 = planes[members[0]].normal;
        let (side_a, side_b): (Vec<usize>, Vec<usize>) = members.iter().partition(|&&i| planes[i].normal.dot(n0) > 0.0);
        let area = |s: &[usize]| s.iter().map(|&i| planes[i].area).sum::<f64>();
        let (front, back) = if area(&side_a) >= area(&side_b) { (side_a, side_b) } else { (side_b, side_a) };
        for &i in &front {
            let f = &planes[i];
            // the mid-plane: half the distance to the partner (or to the face whose partner this is)
            let d = partners[i]
                .filter(|&(_, d)| at_thickness(d))
                .map(|(_, d)| d)
                .or_else(|| partners.iter().find_map(|p| p.filter(|&(j, d)| j == i && at_thickness(d)).map(|(_, d)| d)))
                .unwrap_or(thickness);
            let shift = -f.normal * (d / 2.0);
            let (rings, deviation, arcs) = conservative_rings(f, bend_tolerance);
            let (rings, gained, filled) = narrowest_holes(f, rings, back.iter().map(|&j| &planes[j]), bend_tolerance);
            max_deviation = max_deviation.max(filled);
            let plate_area = f.area + gained;
            max_deviation = max_deviation.max(deviation);
            let lift = |ring: &Vec<DVec3>| -> Vec<DVec3> {
                ring.iter().map(|p| *p - f.normal * (*p - f.point).dot(f.normal) + shift).collect()
            };
            mid_planes.push((f.normal, f.point + shift));
            let mut rings3: Vec<Vec<DVec3>> = rings.iter().map(lift).collect();
            let outline = rings3.remove(0);
            plate_records.push(RecognisedPlate {
                faces: vec![f.face.source.clone()],
                other_side: back.iter().map(|&j| planes[j].face.source.clone()).collect(),
                normal: f.normal,
                area: plate_area,
                holes: rings3.len(),
                arcs,
                pieces: Vec::new(),
            });
            exact_volume += plate_area * thickness;
            sheet.faces.push(SheetFace { outline, holes: rings3 });
        }
    }
    if sheet.faces.is_empty() {
        return Err(RecogniseError::NoPlates);
    }
    // 3. bends
    let cylinders = merge_cylinders(brep, tol);
    let mut bends: Vec<RecognisedBend> = Vec::new();
    let mut used = vec![false; cylinders.len()];
    let mut tessellations: Vec<Option<Vec<DVec3>>> = Vec::new();
    for (i, inner) in cylinders.iter().enumerate() {
        if inner.convex {
            continue;
        }
        let outer = cylinders
            .iter()
            .enumerate()
            .filter(|(j, c)| {
                !used[*j] && c.convex && c.radius > inner.radius && coaxial(inner, c, tol) && angles_overlap(inner, c)
            })
            .min_by(|a, b| a.1.radius.total_cmp(&b.1.radius));
        let Some((j, outer)) = outer else { continue };
        let bend_thickness = outer.radius - inner.radius;
        let (axial, _, _) = ranges(inner, outer);
        if axial[1] - axial[0] <= thickness + sheet_tol && !at_thickness(bend_thickness) {
            // a hole concentric with a rounded corner of a plate: cut edges, not a bend
            continue;
        }
        if !at_thickness(bend_thickness) {
            return Err(RecogniseError::BendThickness {
                inner: brep.faces[inner.faces[0]].source.clone(),
                outer: brep.faces[outer.faces[0]].source.clone(),
                inner_radius: inner.radius,
                outer_radius: outer.radius,
                bend: bend_thickness,
                thickness,
            });
        }
        used[i] = true;
        used[j] = true;
        let (axial, start, angle) = ranges(inner, outer);
        let fitted = Bend {
            center: inner.point,
            axis: inner.axis,
            inner_radius: inner.radius,
            outer_radius: inner.radius + thickness,
            start,
            angle,
            axial,
        };
        let points: Vec<DVec3> = inner.points.iter().chain(&outer.points).copied().collect();
        let bend = fit_to_plates(&fitted, &mid_planes, &sheet.faces, thickness, 10.0 * sheet_tol, &points);
        exact_volume += bend.volume();
        bends.push(RecognisedBend {
            bend,
            inner_faces: inner.faces.iter().map(|&f| brep.faces[f].source.clone()).collect(),
            outer_faces: outer.faces.iter().map(|&f| brep.faces[f].source.clone()).collect(),
            pieces: Vec::new(),
        });
        // a tessellated inner arc (polylines only): its vertices, where the segments must be cut
        let tessellated = inner
            .faces
            .iter()
            .all(|&f| brep.faces[f].loops.iter().flatten().all(|s| matches!(s, Segment::Line { .. })));
        tessellations.push(tessellated.then(|| inner.points.clone()));
    }
    // 4. pieces
    let (base, counts) = sheet
        .build_part_counted(name, options.density, options.decomposition)
        .map_err(|source| plate_error(source, &plate_records))?;
    let plates: Vec<Plate> = base.plates;
    let mut components = base.components;
    let mut next = 0;
    for (record, count) in plate_records.iter_mut().zip(counts) {
        record.pieces = (next..next + count).collect();
        next += count;
    }
    for (b, tessellation) in bends.iter_mut().zip(&tessellations) {
        // a bend given by chords (a mesh) is cut at its own vertices; an exact one at equal angles
        let cuts = match tessellation {
            Some(points) => {
                let angles: Vec<f64> =
                    points.iter().map(|p| angle_of(b.bend.axis, b.bend.start, b.bend.center, *p)).collect();
                b.bend.cuts_among(&angles, bend_tolerance)
            }
            None => {
                let n = b.bend.segments_within(bend_tolerance);
                (0..=n).map(|k| b.bend.angle * k as f64 / n as f64).collect()
            }
        };
        let pieces = b.bend.segments_at(&cuts).map_err(|source| RecogniseError::Bend {
            inner: b.inner_faces.first().cloned().unwrap_or(FaceSource::Step { entity: 0 }),
            source,
        })?;
        max_deviation = max_deviation.max(b.bend.deviation_at(&cuts));
        b.pieces = (components.len()..components.len() + pieces.len()).collect();
        components.extend(pieces);
    }
    // 5. the checks: no two plates or bends overlap, and every boundary point lies inside the pieces
    let plate_count = plate_records.len();
    let owners: Vec<(usize, FaceSource)> = plate_records
        .iter()
        .enumerate()
        .flat_map(|(k, p)| {
            let face = p.faces.first().cloned().unwrap_or(FaceSource::Step { entity: 0 });
            p.pieces.iter().map(move |_| (k, face.clone()))
        })
        .chain(bends.iter().enumerate().flat_map(|(k, b)| {
            let face = b.inner_faces.first().cloned().unwrap_or(FaceSource::Step { entity: 0 });
            b.pieces.iter().map(move |_| (plate_count + k, face.clone()))
        }))
        .collect();
    check_overlap(&components, &owners, 10.0 * sheet_tol)?;
    check_cover(brep, &components, tol.max(1e-9 * diagonal(&components)), thickness, &partners, &planes)?;
    let solid_volume = brep.volume.unwrap_or(exact_volume);
    let max_deviation = max_deviation + chord;
    let origin = PartOrigin::RecognisedSheet {
        thickness,
        plates: plate_records.len(),
        bends: bends.len(),
        solid_volume,
        max_deviation,
    };
    let mut part = Part::from_components(name, components, options.density, origin)?;
    part.plates = plates;
    let pieces_volume = part.mass.volume;
    tracing::debug!(
        name,
        thickness,
        plates = plate_records.len(),
        bends = bends.len(),
        pieces = part.components.len(),
        solid_volume,
        pieces_volume,
        max_deviation,
        "recognised sheet metal"
    );
    let recognition = Recognition {
        thickness,
        plates: plate_records,
        bends,
        solid_volume,
        pieces_volume,
        max_deviation,
        bend_tolerance: options.bend_tolerance,
        tessellation: brep.tessellation,
    };
    Ok((part, recognition))
}

fn plate_error(source: SheetMetalError, plates: &[RecognisedPlate]) -> RecogniseError {
    let face = match &source {
        SheetMetalError::NonFinite { face, .. }
        | SheetMetalError::TooFewVertices { face, .. }
        | SheetMetalError::ZeroArea { face, .. }
        | SheetMetalError::NonPlanar { face, .. }
        | SheetMetalError::SelfIntersecting { face, .. }
        | SheetMetalError::HoleNotInside { face, .. }
        | SheetMetalError::HolesOverlap { face, .. }
        | SheetMetalError::Triangulation { face, .. }
        | SheetMetalError::Prism { face, .. } => Some(*face),
        _ => None,
    };
    let face = face
        .and_then(|f| plates.get(f))
        .and_then(|p| p.faces.first().cloned())
        .unwrap_or(FaceSource::Step { entity: 0 });
    RecogniseError::Plate { face, source }
}

fn diagonal(components: &[ConvexPolytope]) -> f64 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for c in components {
        let (a, b) = c.aabb();
        lo = lo.min(a);
        hi = hi.max(b);
    }
    (hi - lo).length()
}

/// A planar face's frame, 2-D rings (arcs sampled) and exact area; `None` for a face without a usable loop.
fn planar_face(face: &BrepFace, point: DVec3, normal: DVec3) -> Option<PlanarFace<'_>> {
    let normal = normal.normalize_or_zero();
    if normal == DVec3::ZERO || face.loops.is_empty() {
        return None;
    }
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let to2 = |p: DVec3| DVec2::new((p - point).dot(u), (p - point).dot(v));
    let rings: Vec<Vec<DVec2>> = face
        .loops
        .iter()
        .map(|lp| {
            let mut ring = Vec::new();
            for s in lp {
                let n = (s.sweep() / ARC_STEP).ceil().max(1.0) as usize;
                let pts = s.points(n);
                ring.extend(pts[..pts.len() - 1].iter().map(|p| to2(*p)));
            }
            ring
        })
        .filter(|r| r.len() >= 3)
        .collect();
    if rings.is_empty() {
        return None;
    }
    // outline minus holes, whatever the loops' orientation
    let areas: Vec<f64> = face.loops.iter().map(|lp| loop_area(lp, normal).abs()).collect();
    let largest = areas.iter().copied().fold(0.0, f64::max);
    let area = 2.0 * largest - areas.iter().sum::<f64>();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for lp in &face.loops {
        for s in lp {
            for p in s.points((s.sweep() / ARC_STEP).ceil().max(1.0) as usize) {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    Some(PlanarFace { face, point, normal, u, v, rings, area, lo, hi })
}

/// Whether the projections of two faces overlap: sample points inside `a` (a grid over its box) inside `b`.
fn overlaps(a: &PlanarFace<'_>, b: &PlanarFace<'_>) -> bool {
    // b's rings in a's frame
    let to_a = |q: DVec2| {
        let p = b.point + b.u * q.x + b.v * q.y;
        DVec2::new((p - a.point).dot(a.u), (p - a.point).dot(a.v))
    };
    let b_rings: Vec<Vec<DVec2>> = b.rings.iter().map(|r| r.iter().map(|q| to_a(*q)).collect()).collect();
    let inside = |rings: &[Vec<DVec2>], p: DVec2| {
        rings.iter().filter(|r| point_in_ring(p, r) == PointInRing::Inside).count() % 2 == 1
    };
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for q in &a.rings[0] {
        lo = lo.min(*q);
        hi = hi.max(*q);
    }
    const GRID: usize = 24;
    for i in 0..GRID {
        for j in 0..GRID {
            let p = lo + (hi - lo) * DVec2::new((i as f64 + 0.5) / GRID as f64, (j as f64 + 0.5) / GRID as f64);
            if inside(&a.rings, p) && inside(&b_rings, p) {
                return true;
            }
        }
    }
    false
}

/// The nearest opposite face behind face `i` whose projection overlaps it, and its distance.
fn partner(planes: &[PlanarFace<'_>], i: usize, tol: f64) -> Option<(usize, f64)> {
    let a = &planes[i];
    let mut best: Option<(usize, f64)> = None;
    for (j, b) in planes.iter().enumerate() {
        if j == i || a.normal.dot(b.normal) > -1.0 + 1e-6 {
            continue;
        }
        let d = -(b.point - a.point).dot(a.normal);
        if d <= tol || best.is_some_and(|(_, e)| e <= d) {
            continue;
        }
        // boxes must overlap in the plane directions (cheap rejection)
        let slack = DVec3::splat(d + tol);
        if (0..3).any(|k| a.lo[k] > b.hi[k] + slack[k] || b.lo[k] > a.hi[k] + slack[k]) {
            continue;
        }
        if overlaps(a, b) || overlaps(b, a) {
            best = Some((j, d));
        }
    }
    best
}

/// The loops of a planar face as polygons that never cut into the material (see the module documentation), outer
/// first, with the largest deviation from the true loops and the number of arcs.
fn conservative_rings(f: &PlanarFace<'_>, tolerance: f64) -> (Vec<Vec<DVec3>>, f64, usize) {
    let n = f.normal;
    // orient: the outer (largest) loop counter-clockwise about the normal, the others clockwise
    let areas: Vec<f64> = f.face.loops.iter().map(|lp| loop_area(lp, n)).collect();
    let outer = (0..areas.len()).max_by(|&a, &b| areas[a].abs().total_cmp(&areas[b].abs())).unwrap_or(0);
    let mut order = vec![outer];
    order.extend((0..areas.len()).filter(|&k| k != outer));
    let mut deviation: f64 = 0.0;
    let mut arcs = 0;
    let mut out = Vec::new();
    for k in order {
        let lp = &f.face.loops[k];
        let want_ccw = k == outer;
        let reverse = (areas[k] > 0.0) != want_ccw;
        let segments: Vec<Segment> =
            if reverse { lp.iter().rev().map(Segment::reversed).collect() } else { lp.clone() };
        let mut ring: Vec<DVec3> = Vec::new();
        for s in &segments {
            match *s {
                Segment::Line { start, .. } => ring.push(start),
                Segment::Arc { center, axis, radius, start, end } => {
                    arcs += 1;
                    let phi = s.sweep();
                    // with the face on the left, the material lies on the centre side iff the arc turns
                    // counter-clockwise about the outward normal
                    let tangents = axis.dot(n) > 0.0;
                    let steps = arc_steps(radius, phi, tolerance, tangents);
                    let delta = phi / steps as f64;
                    let (u0, w) = (start - center, axis.cross(start - center));
                    let at = |a: f64, r: f64| center + (u0 * a.cos() + w * a.sin()) * (r / radius);
                    if tangents {
                        deviation = deviation.max(radius * (1.0 / (delta / 2.0).cos() - 1.0));
                        if start != end {
                            ring.push(start);
                        }
                        let corner = radius / (delta / 2.0).cos();
                        ring.extend((0..steps).map(|i| at(delta * (i as f64 + 0.5), corner)));
                    } else {
                        deviation = deviation.max(radius * (1.0 - (delta / 2.0).cos()));
                        ring.extend((0..steps).map(|i| at(delta * i as f64, radius)));
                    }
                    let _ = end;
                }
            }
        }
        out.push(ring);
    }
    (out, deviation, arcs)
}

/// The holes of a plate's front face narrowed to the other side's: a hole of a face on the other side whose
/// projection lies inside a hole of the front face and is smaller replaces it (the smallest such), so that the
/// plate's hole is the narrowest section of a countersunk or counterbored hole and never cuts into material. A hole
/// of the other side that only overlaps one of the front's is left to the cover check. Returns the rings, the area
/// the plate gains (mm^2) and how far the pieces may then stand outside the solid (mm): the widest gap between a
/// narrowed hole and the front's, which the plate fills (a countersink's cone).
fn narrowest_holes<'a>(
    f: &PlanarFace<'_>,
    mut rings: Vec<Vec<DVec3>>,
    back: impl Iterator<Item = &'a PlanarFace<'a>>,
    tolerance: f64,
) -> (Vec<Vec<DVec3>>, f64, f64) {
    let to2 = |p: DVec3| DVec2::new((p - f.point).dot(f.u), (p - f.point).dot(f.v));
    let flat = |ring: &[DVec3]| -> Vec<DVec2> { ring.iter().map(|p| to2(*p)).collect() };
    let area = |ring: &[DVec2]| {
        let n = ring.len();
        (0..n).map(|k| ring[k].perp_dot(ring[(k + 1) % n])).sum::<f64>().abs() / 2.0
    };
    let inside =
        |inner: &[DVec2], outer: &[DVec2]| inner.iter().all(|q| point_in_ring(*q, outer) != PointInRing::Outside);
    let back_holes: Vec<Vec<DVec3>> =
        back.flat_map(|b| conservative_rings(b, tolerance).0.into_iter().skip(1)).collect();
    let front_holes: Vec<Vec<DVec2>> = rings.iter().skip(1).map(|r| flat(r)).collect();
    let mut gained = 0.0;
    for hole in rings.iter_mut().skip(1) {
        let h2 = flat(hole);
        let own = area(&h2);
        let mut best = own * (1.0 - 1e-9);
        let mut narrower: Option<&Vec<DVec3>> = None;
        for b in &back_holes {
            let b2 = flat(b);
            let a = area(&b2);
            if a < best && inside(&b2, &h2) {
                best = a;
                narrower = Some(b);
            }
        }
        if let Some(b) = narrower {
            // onto the front face's plane, in the front's hole orientation (clockwise about its normal)
            let mut ring: Vec<DVec3> = b.iter().map(|p| *p - f.normal * (*p - f.point).dot(f.normal)).collect();
            let o = ring[0];
            let signed: f64 = (1..ring.len() - 1).map(|k| (ring[k] - o).cross(ring[k + 1] - o).dot(f.normal)).sum();
            if signed > 0.0 {
                ring.reverse();
            }
            *hole = ring;
            gained += own - best;
        }
    }
    // the pieces fill every hole of either side around a hole of the plate, up to that hole
    let mut filled: f64 = 0.0;
    let wider: Vec<Vec<DVec2>> = front_holes.into_iter().chain(back_holes.iter().map(|b| flat(b))).collect();
    for hole in rings.iter().skip(1) {
        let h2 = flat(hole);
        let gap = |q: DVec2| {
            (0..h2.len())
                .map(|k| {
                    let (a, c) = (h2[k], h2[(k + 1) % h2.len()]);
                    let ac = c - a;
                    let len2 = ac.length_squared();
                    let s = if len2 > 0.0 { ((q - a).dot(ac) / len2).clamp(0.0, 1.0) } else { 0.0 };
                    (a + s * ac - q).length()
                })
                .fold(f64::INFINITY, f64::min)
        };
        for w in wider.iter().filter(|w| area(w) > area(&h2) * (1.0 + 1e-9) && inside(&h2, w)) {
            filled = w.iter().map(|q| gap(*q)).fold(filled, f64::max);
        }
    }
    (rings, gained, filled)
}

/// Steps for an arc of radius `r` and sweep `phi` within `tolerance`: tangents deviate by `r (1/cos(d/2) - 1)`,
/// chords by `r (1 - cos(d/2))`; at least one step per 60 degrees, at most 4096.
fn arc_steps(r: f64, phi: f64, tolerance: f64, tangents: bool) -> usize {
    let c = if tangents { r / (r + tolerance) } else { 1.0 - (tolerance / r).min(1.0) };
    let delta = 2.0 * c.clamp(-1.0, 1.0).acos();
    let by_tolerance = if delta > 0.0 { (phi / delta).ceil() } else { 4096.0 };
    let by_angle = (phi / std::f64::consts::FRAC_PI_3).ceil();
    (by_tolerance.max(by_angle).max(1.0) as usize).min(4096)
}

/// Cylindrical faces merged by axis line, radius and side.
fn merge_cylinders(brep: &Brep, tol: f64) -> Vec<Cylinder> {
    let mut out: Vec<Cylinder> = Vec::new();
    for (index, face) in brep.faces.iter().enumerate() {
        let Surface::Cylinder { point, axis, radius, convex } = face.surface else { continue };
        let axis = axis.normalize_or_zero();
        if axis == DVec3::ZERO || radius.is_nan() || radius <= 0.0 {
            continue;
        }
        let points = face.boundary_points(ARC_STEP);
        let candidate = Cylinder { point, axis, radius, convex, faces: vec![index], points };
        match out
            .iter_mut()
            .find(|c| c.convex == convex && (c.radius - radius).abs() <= tol && coaxial(c, &candidate, tol))
        {
            Some(c) => {
                c.faces.push(index);
                c.points.extend(candidate.points);
            }
            None => out.push(candidate),
        }
    }
    out
}

/// Whether two cylinders share their axis line (within `tol` over their extent).
fn coaxial(a: &Cylinder, b: &Cylinder, tol: f64) -> bool {
    let cross = a.axis.cross(b.axis).length();
    let extent = a.points.iter().chain(&b.points).map(|p| (*p - a.point).length()).fold(a.radius, f64::max);
    if cross * extent > tol.max(1e-9 * extent) * 10.0 {
        return false;
    }
    let d = b.point - a.point;
    (d - a.axis * d.dot(a.axis)).length() <= 10.0 * tol.max(1e-9 * extent)
}

/// The angles of points about a cylinder's axis, measured from `start`.
fn angle_of(axis: DVec3, start: DVec3, center: DVec3, p: DVec3) -> f64 {
    let d = p - center;
    let w = axis.cross(start);
    let a = d.dot(w).atan2(d.dot(start));
    if a < 0.0 { a + std::f64::consts::TAU } else { a }
}

/// The smallest angular interval containing the points' angles: `(start direction, angle)`.
fn angle_range(axis: DVec3, center: DVec3, points: &[DVec3]) -> (DVec3, f64) {
    let reference = points
        .iter()
        .map(|p| {
            let d = *p - center;
            d - axis * d.dot(axis)
        })
        .find(|d| d.length() > 0.0)
        .map(|d| d.normalize())
        .unwrap_or_else(|| axis.any_orthonormal_vector());
    let mut angles: Vec<f64> = points.iter().map(|p| angle_of(axis, reference, center, *p)).collect();
    angles.sort_by(f64::total_cmp);
    if angles.is_empty() {
        return (reference, 0.0);
    }
    // the largest gap (cyclically) is outside the range
    let mut gap = angles[0] + std::f64::consts::TAU - angles[angles.len() - 1];
    let mut start_angle = angles[0];
    for k in 1..angles.len() {
        let g = angles[k] - angles[k - 1];
        if g > gap {
            gap = g;
            start_angle = angles[k];
        }
    }
    let w = axis.cross(reference);
    let start = reference * start_angle.cos() + w * start_angle.sin();
    (start, std::f64::consts::TAU - gap)
}

/// Whether the angle ranges of two coaxial cylinders overlap.
fn angles_overlap(a: &Cylinder, b: &Cylinder) -> bool {
    let (start, angle) = angle_range(a.axis, a.point, &a.points);
    let (start_b, angle_b) = angle_range(a.axis, a.point, &b.points);
    let sb = angle_of(a.axis, start, a.point, a.point + start_b);
    let eb = sb + angle_b;
    // b's interval [sb, eb] against a's [0, angle], cyclically
    let tau = std::f64::consts::TAU;
    let hit = |lo: f64, hi: f64| lo < angle - 1e-9 && hi > 1e-9;
    hit(sb, eb) || hit(sb - tau, eb - tau)
}

/// A bend's axial interval (about the inner cylinder's axis point), start direction and angle from both cylinders.
fn ranges(inner: &Cylinder, outer: &Cylinder) -> ([f64; 2], DVec3, f64) {
    let points: Vec<DVec3> = inner.points.iter().chain(&outer.points).copied().collect();
    let (lo, hi) = points
        .iter()
        .map(|p| (*p - inner.point).dot(inner.axis))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| (lo.min(z), hi.max(z)));
    let (start, angle) = angle_range(inner.axis, inner.point, &points);
    ([lo, hi], start, angle)
}

/// The bend rebuilt from the two plates it joins, so that its end faces lie on the plates' ends and its radial
/// sides on their skins (to rounding, whatever the precision of the fitted cylinders): the axis is parallel to
/// both plates at `r + t / 2` from their mid-planes on the fitted axis' side, the bend starts square to one plate and
/// ends square to the other. A plate joins the bend when it is parallel to the axis at that distance and its outline
/// has a corner on the bend's tangent line (within `tol`). Without exactly two such plates that are not parallel (a
/// bend between two bends, a hem) the fitted bend is kept.
fn fit_to_plates(
    fitted: &Bend,
    mid_planes: &[(DVec3, DVec3)],
    faces: &[SheetFace],
    thickness: f64,
    tol: f64,
    points: &[DVec3],
) -> Bend {
    let a = fitted.axis;
    let c = fitted.center;
    let mid = fitted.inner_radius + thickness / 2.0;
    let mut joined: Vec<(DVec3, DVec3, f64)> = Vec::new();
    for ((n, p), face) in mid_planes.iter().zip(faces) {
        if n.dot(a).abs() > 1e-6 {
            continue;
        }
        let offset = n.dot(c - *p);
        if (offset.abs() - mid).abs() > tol {
            continue;
        }
        let side = offset.signum();
        // the tangent line: the axis moved onto the plate
        let foot = c - *n * (side * mid);
        let on_line = face.outline.iter().any(|q| {
            let d = *q - foot;
            (d - a * d.dot(a)).length() <= tol
        });
        if on_line {
            joined.push((*n, *p, side));
        }
    }
    let [(n1, p1, s1), (n2, p2, s2)] = joined[..] else {
        tracing::debug!(plates = joined.len(), "a bend joins other than two plates: its fitted cylinders are kept");
        return *fitted;
    };
    let cross = n1.cross(n2);
    if cross.length() < 1e-6 {
        return *fitted;
    }
    let mut axis = cross.normalize();
    if axis.dot(a) < 0.0 {
        axis = -axis;
    }
    // the centre: n1 . x = s1 mid, n2 . x = s2 mid (from the planes' points), axis . x = axis . c
    let rows = glam::DMat3::from_cols(n1, n2, axis).transpose();
    let rhs = DVec3::new(n1.dot(p1) + s1 * mid, n2.dot(p2) + s2 * mid, axis.dot(c));
    if rows.determinant().abs() < 1e-12 {
        return *fitted;
    }
    let center = rows.inverse() * rhs;
    let (u0, u1) = (-n1 * s1, -n2 * s2);
    let mut angle = axis.dot(u0.cross(u1)).atan2(u0.dot(u1));
    // counter-clockwise about the axis from the start: from the first plate's side to the second's, or back
    let start = if angle >= 0.0 { u0 } else { u1 };
    angle = angle.abs();
    if !(angle > 1e-9 && (angle - fitted.angle).abs() < 0.1 + 0.1 * fitted.angle) {
        return *fitted;
    }
    let (lo, hi) = points
        .iter()
        .map(|q| (*q - center).dot(axis))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), z| (l.min(z), h.max(z)));
    Bend { center, axis, start, angle, axial: [lo, hi], ..*fitted }
}

/// Checks that no two pieces of different plates or bends overlap by more than `depth`: separating-axis tests on
/// the pieces' face normals and the cross products of their edges (exact for convex polytopes), after a box test.
/// O(P^2) box tests and O(F E^2 V) per pair whose boxes meet.
fn check_overlap(
    components: &[ConvexPolytope],
    owners: &[(usize, FaceSource)],
    depth: f64,
) -> Result<(), RecogniseError> {
    let boxes: Vec<(DVec3, DVec3)> = components.iter().map(ConvexPolytope::aabb).collect();
    for i in 0..components.len() {
        for j in i + 1..components.len() {
            if owners[i].0 == owners[j].0
                || (0..3).any(|k| boxes[i].1[k] <= boxes[j].0[k] + depth || boxes[j].1[k] <= boxes[i].0[k] + depth)
            {
                continue;
            }
            if interiors_overlap(&components[i], &components[j], depth) {
                return Err(RecogniseError::Overlap { a: owners[i].1.clone(), b: owners[j].1.clone() });
            }
        }
    }
    Ok(())
}

/// Whether two convex polytopes overlap by more than `depth` along every candidate separating axis.
fn interiors_overlap(a: &ConvexPolytope, b: &ConvexPolytope, depth: f64) -> bool {
    let separated_along = |axis: DVec3| {
        let len = axis.length();
        if len < 1e-12 {
            return false;
        }
        let axis = axis / len;
        let range = |c: &ConvexPolytope| {
            c.vertices()
                .iter()
                .map(|v| v.dot(axis))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)))
        };
        let ((la, ha), (lb, hb)) = (range(a), range(b));
        ha <= lb + depth || hb <= la + depth
    };
    if a.planes().chain(b.planes()).any(|p| separated_along(p.normal)) {
        return false;
    }
    let directions = |c: &ConvexPolytope| -> Vec<DVec3> {
        c.edges().iter().map(|e| c.vertices()[e.vertices[1]] - c.vertices()[e.vertices[0]]).collect()
    };
    let (da, db) = (directions(a), directions(b));
    !da.iter().any(|u| db.iter().any(|w| separated_along(u.cross(*w))))
}

/// Checks that every boundary point of the solid lies in the union of the pieces (within `tol`).
fn check_cover(
    brep: &Brep,
    components: &[ConvexPolytope],
    tol: f64,
    thickness: f64,
    partners: &[Option<(usize, f64)>],
    planes: &[PlanarFace<'_>],
) -> Result<(), RecogniseError> {
    let boxes: Vec<(DVec3, DVec3)> = components.iter().map(ConvexPolytope::aabb).collect();
    for face in &brep.faces {
        for p in face.boundary_points(ARC_STEP) {
            let mut best = f64::INFINITY;
            for (c, (lo, hi)) in components.iter().zip(&boxes) {
                if (0..3).any(|k| p[k] < lo[k] - tol || p[k] > hi[k] + tol) {
                    let outside = (*lo - p).max(p - *hi).max(DVec3::ZERO).length();
                    best = best.min(outside.max(tol * 2.0));
                    continue;
                }
                let d = c.planes().map(|pl| pl.signed_distance(p)).fold(f64::NEG_INFINITY, f64::max);
                best = best.min(d);
                if best <= tol {
                    break;
                }
            }
            if best > tol {
                // of the planar faces through the point with an opposite face at another distance than the sheet's,
                // the one nearest the sheet's thickness says best where the solid is no sheet
                let culprit = planes
                    .iter()
                    .enumerate()
                    .filter(|(_, q)| (p - q.point).dot(q.normal).abs() <= 10.0 * tol)
                    .filter_map(|(k, q)| partners[k].map(|(j, d)| (q, j, d)))
                    .filter(|(_, _, d)| (d - thickness).abs() > 2.0 * tol.max(thickness * 1e-6))
                    .min_by(|x, y| (x.2 - thickness).abs().total_cmp(&(y.2 - thickness).abs()));
                if let Some((q, j, d)) = culprit {
                    return Err(RecogniseError::NotConstantThickness {
                        a: q.face.source.clone(),
                        b: planes[j].face.source.clone(),
                        distance: d,
                        thickness,
                    });
                }
                return Err(RecogniseError::Outside { face: face.source.clone(), point: p, distance: best, thickness });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
