//! From the entity instances of a STEP file to a [`Brep`]: choosing the solid, finding its length unit, and walking
//! solid -> shell -> faces -> bounds -> loops -> edges -> curves and vertices -> points.

use super::StepOptions;
use super::p21::{Body, Exchange, Instance, Record, Value};
use crate::cad::geometry::Frame;
use crate::cad::{Brep, BrepFace, FaceSource, Segment, Surface, loop_area};
use crate::io::{IoError, Place, check_coordinate};
use glam::DVec3;
use std::collections::HashSet;
use std::path::Path;

/// Deepest chain of unit definitions (`CONVERSION_BASED_UNIT` of another unit) and of curves wrapping curves
/// (`SURFACE_CURVE` of a `SEAM_CURVE`...) followed; real files use 1 or 2, and a cycle stops here with an error.
const MAX_CHAIN: usize = 8;

/// Builds the B-rep of the chosen solid.
pub(super) fn build(ex: &Exchange, file: &Path, options: &StepOptions) -> Result<Brep, IoError> {
    let mut graph = Graph { ex, file, scale: 1.0, angle: 1.0 };
    let solids = graph.solids()?;
    let solid = match (options.solid, solids.len()) {
        (_, 0) => {
            return Err(IoError::Empty {
                file: file.to_path_buf(),
                at: Place::WholeFile,
                what: "no solid (MANIFOLD_SOLID_BREP or CLOSED_SHELL) in the STEP file",
            });
        }
        (None, 1) => solids[0],
        (None, count) => return Err(IoError::SeveralSolids { file: file.to_path_buf(), count }),
        (Some(index), count) => {
            *solids.get(index).ok_or_else(|| IoError::NoSuchSolid { file: file.to_path_buf(), index, count })?
        }
    };
    graph.scale = graph.length_scale(solid)?;
    match graph.solid_faces(solid) {
        Ok(faces) => Ok(Brep { faces, volume: None, tessellation: None }),
        Err(IoError::Unsupported { at, kind, role: role @ ("faces" | "edges"), .. }) => {
            tracing::debug!(file = %file.display(), %at, kind, role, "the solid is tessellated");
            graph.angle = graph.angle_scale(solid)?;
            super::tessellated_brep(&graph, solid, options)
        }
        Err(e) => Err(e),
    }
}

/// The instances and the length unit (mm per file unit).
pub(super) struct Graph<'a> {
    pub(super) ex: &'a Exchange,
    pub(super) file: &'a Path,
    pub(super) scale: f64,
    /// Radians per plane-angle unit (read only where a surface needs it: a cone's semi-angle).
    pub(super) angle: f64,
}

/// One simple instance and its number, for reading arguments with located errors.
#[derive(Clone, Copy)]
pub(super) struct Entity<'a> {
    pub(super) id: u64,
    pub(super) rec: &'a Record,
    pub(super) file: &'a Path,
}

fn describe(v: &Value) -> String {
    match v {
        Value::Integer(i) => format!("the integer {i}"),
        Value::Real(r) => format!("the number {r}"),
        Value::String(_) => "a string".into(),
        Value::Enum(e) => format!(".{e}."),
        Value::Binary(_) => "a binary".into(),
        Value::Ref(n) => format!("#{n}"),
        Value::Unset => "$".into(),
        Value::Derived => "*".into(),
        Value::List(_) => "a list".into(),
        Value::Typed(name, _) => format!("a {name}"),
    }
}

/// A plain or typed (`LENGTH_MEASURE(2.)`) number.
pub(super) fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Real(r) => Some(*r),
        Value::Integer(i) => Some(*i as f64),
        Value::Typed(_, inner) => number(inner),
        _ => None,
    }
}

impl<'a> Entity<'a> {
    pub(super) fn error(&self, message: String) -> IoError {
        IoError::Syntax { file: self.file.to_path_buf(), at: Place::Entity(self.id), message }
    }

    pub(super) fn name(&self) -> &'a str {
        &self.rec.name
    }

    /// Requires exactly `n` arguments.
    pub(super) fn arity(&self, n: usize) -> Result<(), IoError> {
        let got = self.rec.args.len();
        if got == n { Ok(()) } else { Err(self.error(format!("{} needs {n} arguments, got {got}", self.name()))) }
    }

    pub(super) fn arg(&self, i: usize) -> Result<&'a Value, IoError> {
        self.rec.args.get(i).ok_or_else(|| {
            self.error(format!("{} needs at least {} arguments, got {}", self.name(), i + 1, self.rec.args.len()))
        })
    }

    pub(super) fn wrong(&self, i: usize, what: &str, expected: &str, got: &Value) -> IoError {
        self.error(format!("{}: argument {} ({what}) must be {expected}, got {}", self.name(), i + 1, describe(got)))
    }

    pub(super) fn reference(&self, i: usize, what: &str) -> Result<u64, IoError> {
        match self.arg(i)? {
            Value::Ref(n) => Ok(*n),
            other => Err(self.wrong(i, what, "a reference", other)),
        }
    }

    pub(super) fn number(&self, i: usize, what: &str) -> Result<f64, IoError> {
        let v = self.arg(i)?;
        number(v).filter(|x| x.is_finite()).ok_or_else(|| self.wrong(i, what, "a finite number", v))
    }

    pub(super) fn integer(&self, i: usize, what: &str) -> Result<i64, IoError> {
        match self.arg(i)? {
            Value::Integer(n) => Ok(*n),
            other => Err(self.wrong(i, what, "an integer", other)),
        }
    }

    pub(super) fn logical(&self, i: usize, what: &str) -> Result<bool, IoError> {
        match self.arg(i)? {
            Value::Enum(e) if e == "T" => Ok(true),
            Value::Enum(e) if e == "F" => Ok(false),
            other => Err(self.wrong(i, what, ".T. or .F.", other)),
        }
    }

    pub(super) fn list(&self, i: usize, what: &str) -> Result<&'a [Value], IoError> {
        match self.arg(i)? {
            Value::List(items) => Ok(items),
            other => Err(self.wrong(i, what, "a list", other)),
        }
    }

    /// A list of references.
    pub(super) fn references(&self, i: usize, what: &str) -> Result<Vec<u64>, IoError> {
        self.list(i, what)?
            .iter()
            .map(|v| match v {
                Value::Ref(n) => Ok(*n),
                other => Err(self.wrong(i, what, "a list of references", other)),
            })
            .collect()
    }
}

/// Every reference in `values`, nested lists included.
fn collect_refs(values: &[Value], out: &mut Vec<u64>) {
    let mut stack: Vec<&Value> = values.iter().collect();
    while let Some(v) = stack.pop() {
        match v {
            Value::Ref(n) => out.push(*n),
            Value::List(items) => stack.extend(items.iter()),
            Value::Typed(_, inner) => stack.push(inner),
            _ => {}
        }
    }
}

/// The records of an instance.
pub(super) fn records(inst: &Instance) -> &[Record] {
    match &inst.body {
        Body::Simple(r) => std::slice::from_ref(r),
        Body::Complex(rs) => rs,
    }
}

/// mm per unit of an SI prefix applied to the metre.
fn si_prefix_mm(prefix: &str) -> Option<f64> {
    let factor = match prefix {
        "EXA" => 1e18,
        "PETA" => 1e15,
        "TERA" => 1e12,
        "GIGA" => 1e9,
        "MEGA" => 1e6,
        "KILO" => 1e3,
        "HECTO" => 1e2,
        "DECA" => 1e1,
        "DECI" => 1e-1,
        "CENTI" => 1e-2,
        "MILLI" => 1e-3,
        "MICRO" => 1e-6,
        "NANO" => 1e-9,
        "PICO" => 1e-12,
        "FEMTO" => 1e-15,
        "ATTO" => 1e-18,
        _ => return None,
    };
    Some(1000.0 * factor)
}

/// Reverses a closed loop: the segments in the other order, each traversed the other way.
fn reverse_loop(lp: &mut [Segment]) {
    lp.reverse();
    for s in lp.iter_mut() {
        *s = s.reversed();
    }
}

/// Puts the loop of largest absolute area first and counter-clockwise about `normal`, the others clockwise.
fn orient_planar_loops(loops: &mut Vec<Vec<Segment>>, normal: DVec3) {
    let areas: Vec<f64> = loops.iter().map(|lp| loop_area(lp, normal)).collect();
    let Some(outer) = (0..areas.len()).max_by(|&a, &b| areas[a].abs().total_cmp(&areas[b].abs())) else { return };
    for (k, lp) in loops.iter_mut().enumerate() {
        if (k == outer) != (areas[k] > 0.0) {
            reverse_loop(lp);
        }
    }
    let first = loops.remove(outer);
    loops.insert(0, first);
}

impl<'a> Graph<'a> {
    pub(super) fn instance(&self, id: u64, from: u64) -> Result<&'a Instance, IoError> {
        self.ex.instances.get(&id).ok_or_else(|| IoError::MissingReference {
            file: self.file.to_path_buf(),
            at: Place::Entity(from),
            target: id,
        })
    }

    pub(super) fn syntax(&self, at: u64, message: String) -> IoError {
        IoError::Syntax { file: self.file.to_path_buf(), at: Place::Entity(at), message }
    }

    /// Instance `id`, referenced from `from`, which must be a simple instance of one of the `expected` types.
    pub(super) fn expect(&self, id: u64, from: u64, expected: &[&str]) -> Result<Entity<'a>, IoError> {
        let inst = self.instance(id, from)?;
        match &inst.body {
            Body::Simple(rec) if expected.contains(&rec.name.as_str()) => Ok(Entity { id, rec, file: self.file }),
            _ => Err(self.syntax(from, format!("#{id} is a {}, expected {}", inst.type_name(), expected.join(" or ")))),
        }
    }

    /// Instance `id` as a simple instance of any type, or `None` for a complex one.
    pub(super) fn simple(&self, id: u64, from: u64) -> Result<(Option<Entity<'a>>, &'a Instance), IoError> {
        let inst = self.instance(id, from)?;
        Ok(match &inst.body {
            Body::Simple(rec) => (Some(Entity { id, rec, file: self.file }), inst),
            Body::Complex(_) => (None, inst),
        })
    }

    /// The solids in file order: `MANIFOLD_SOLID_BREP`s and `BREP_WITH_VOIDS`, and `CLOSED_SHELL`s that no solid
    /// (or `ORIENTED_CLOSED_SHELL`) uses.
    fn solids(&self) -> Result<Vec<u64>, IoError> {
        let mut candidates = Vec::new();
        let mut used = HashSet::new();
        let mut refs = Vec::new();
        for &id in &self.ex.order {
            let inst = self.instance(id, id)?;
            for rec in records(inst) {
                match rec.name.as_str() {
                    "MANIFOLD_SOLID_BREP" | "BREP_WITH_VOIDS" | "ORIENTED_CLOSED_SHELL" => {
                        if rec.name != "ORIENTED_CLOSED_SHELL" {
                            candidates.push(id);
                        }
                        refs.clear();
                        collect_refs(&rec.args, &mut refs);
                        used.extend(refs.iter().copied());
                    }
                    "CLOSED_SHELL" => candidates.push(id),
                    _ => {}
                }
            }
        }
        candidates.retain(|id| {
            let is_shell = self.ex.instances.get(id).is_some_and(|i| i.record("CLOSED_SHELL").is_some());
            !(is_shell && used.contains(id))
        });
        candidates.dedup();
        Ok(candidates)
    }

    /// mm per length unit of the file, for `solid`: see the module documentation.
    fn length_scale(&self, solid: u64) -> Result<f64, IoError> {
        if let Some((representation, context)) = self.context_of(solid) {
            let inst = self.instance(context, representation)?;
            if let Some(scale) = self.context_length_unit(context, inst)? {
                return Ok(scale);
            }
        }
        let mut agreed: Option<f64> = None;
        let mut disagree = false;
        for &id in &self.ex.order {
            let inst = self.instance(id, id)?;
            if let Some(scale) = self.context_length_unit(id, inst)? {
                match agreed {
                    None => agreed = Some(scale),
                    Some(s) if s != scale => disagree = true,
                    Some(_) => {}
                }
            }
        }
        match agreed {
            Some(scale) if !disagree => Ok(scale),
            _ => {
                tracing::warn!(
                    file = %self.file.display(),
                    "no length unit found for the solid #{solid}{}; assuming millimetres",
                    if disagree { " (the file's contexts disagree)" } else { "" }
                );
                Ok(1.0)
            }
        }
    }

    /// Radians per plane-angle unit for `solid`: its context's `PLANE_ANGLE_UNIT`, an `SI_UNIT` (radians) or a
    /// `CONVERSION_BASED_UNIT` (`DEGREE`) defined by a `(PLANE_ANGLE_)MEASURE_WITH_UNIT` of radians; radians when the
    /// context names none.
    pub(super) fn angle_scale(&self, solid: u64) -> Result<f64, IoError> {
        let Some((representation, context)) = self.context_of(solid) else { return Ok(1.0) };
        let inst = self.instance(context, representation)?;
        let Some(rec) = inst.record("GLOBAL_UNIT_ASSIGNED_CONTEXT") else { return Ok(1.0) };
        for unit in (Entity { id: context, rec, file: self.file }).references(0, "units")? {
            let u = self.instance(unit, context)?;
            if u.record("PLANE_ANGLE_UNIT").is_none() {
                continue;
            }
            let Some(c) = u.record("CONVERSION_BASED_UNIT") else { return Ok(1.0) };
            let e = Entity { id: unit, rec: c, file: self.file };
            let measure = e.reference(c.args.len().saturating_sub(1), "conversion factor")?;
            let m = self.instance(measure, unit)?;
            let r = ["PLANE_ANGLE_MEASURE_WITH_UNIT", "MEASURE_WITH_UNIT"]
                .iter()
                .filter_map(|name| m.record(name))
                .find(|r| r.args.len() == 2)
                .ok_or_else(|| {
                    self.syntax(unit, format!("#{measure} is a {}, expected a MEASURE_WITH_UNIT", m.type_name()))
                })?;
            let value = Entity { id: measure, rec: r, file: self.file }.number(0, "value")?;
            return if value > 0.0 {
                Ok(value)
            } else {
                Err(self.syntax(measure, format!("a plane angle unit of {value} rad is not positive")))
            };
        }
        Ok(1.0)
    }

    /// The first representation (`..._REPRESENTATION(name, items, context)`) whose items hold `item`, and its
    /// context.
    pub(super) fn context_of(&self, item: u64) -> Option<(u64, u64)> {
        self.ex.order.iter().find_map(|&id| {
            let inst = self.ex.instances.get(&id)?;
            records(inst).iter().find_map(|rec| match rec.args.as_slice() {
                [_, Value::List(items), Value::Ref(context)]
                    if rec.name.ends_with("REPRESENTATION") && items.contains(&Value::Ref(item)) =>
                {
                    Some((id, *context))
                }
                _ => None,
            })
        })
    }

    /// The length unit (mm per unit) of a `GLOBAL_UNIT_ASSIGNED_CONTEXT`, if `inst` is one and names a length unit.
    fn context_length_unit(&self, id: u64, inst: &Instance) -> Result<Option<f64>, IoError> {
        let Some(rec) = inst.record("GLOBAL_UNIT_ASSIGNED_CONTEXT") else { return Ok(None) };
        let units = Entity { id, rec, file: self.file }.references(0, "units")?;
        for unit in units {
            if let Some(scale) = self.unit_scale(unit, id, 0)? {
                return Ok(Some(scale));
            }
        }
        Ok(None)
    }

    /// mm per unit of the unit `id` if it is a length unit, `None` if it is another unit.
    fn unit_scale(&self, id: u64, from: u64, depth: usize) -> Result<Option<f64>, IoError> {
        if depth > MAX_CHAIN {
            return Err(self.syntax(id, format!("unit defined through more than {MAX_CHAIN} other units (a cycle?)")));
        }
        let inst = self.instance(id, from)?;
        let is_length = inst.record("LENGTH_UNIT").is_some();
        let scale = if let Some(rec) = inst.record("SI_UNIT") {
            // Complex form `SI_UNIT(prefix, name)`; the simple form also carries NAMED_UNIT's dimensions first.
            let e = Entity { id, rec, file: self.file };
            let n = rec.args.len();
            if n < 2 {
                return Err(e.error(format!("SI_UNIT needs a prefix and a name, got {n} arguments")));
            }
            match (&rec.args[n - 2], &rec.args[n - 1]) {
                (Value::Unset, Value::Enum(name)) if name == "METRE" => Some(1000.0),
                (Value::Enum(prefix), Value::Enum(name)) if name == "METRE" => {
                    Some(si_prefix_mm(prefix).ok_or_else(|| e.error(format!("unknown SI prefix .{prefix}.")))?)
                }
                (_, Value::Enum(_)) => None,
                (_, other) => return Err(e.wrong(n - 1, "name", "an SI unit name", other)),
            }
        } else if let Some(rec) = inst.record("CONVERSION_BASED_UNIT") {
            let e = Entity { id, rec, file: self.file };
            let measure = e.reference(rec.args.len().saturating_sub(1), "conversion factor")?;
            self.measure_with_unit(measure, id, depth)?
        } else {
            None
        };
        match scale {
            Some(s) if !(s.is_finite() && s > 0.0) => {
                Err(self.syntax(id, format!("length unit of {s} mm is not positive and finite")))
            }
            None if is_length => {
                tracing::debug!(file = %self.file.display(), "length unit #{id} ({}) is not understood", inst.type_name());
                Ok(None)
            }
            other => Ok(other),
        }
    }

    /// `value x unit` (mm) of a `(LENGTH_)MEASURE_WITH_UNIT(value, unit)`, `None` if the unit is not a length.
    fn measure_with_unit(&self, id: u64, from: u64, depth: usize) -> Result<Option<f64>, IoError> {
        let inst = self.instance(id, from)?;
        let rec = ["LENGTH_MEASURE_WITH_UNIT", "MEASURE_WITH_UNIT"]
            .iter()
            .filter_map(|name| inst.record(name))
            .find(|r| r.args.len() == 2)
            .ok_or_else(|| {
                self.syntax(from, format!("#{id} is a {}, expected a MEASURE_WITH_UNIT", inst.type_name()))
            })?;
        let e = Entity { id, rec, file: self.file };
        let value = e.number(0, "value")?;
        let unit = e.reference(1, "unit")?;
        Ok(self.unit_scale(unit, id, depth + 1)?.map(|s| value * s))
    }

    /// The faces of a solid (or of a closed shell taken as one).
    fn solid_faces(&self, solid: u64) -> Result<Vec<BrepFace>, IoError> {
        let (shell, faces, flip) = self.shell(solid)?;
        let mut out = Vec::with_capacity(faces.len());
        for f in faces {
            out.push(self.face(f, shell, flip)?);
        }
        Ok(out)
    }

    /// The closed shell of a solid, its faces, and whether the solid uses it reversed.
    pub(super) fn shell(&self, solid: u64) -> Result<(u64, Vec<u64>, bool), IoError> {
        let e = self.expect(solid, solid, &["MANIFOLD_SOLID_BREP", "CLOSED_SHELL", "BREP_WITH_VOIDS"])?;
        let (shell, flip) = match e.name() {
            "CLOSED_SHELL" => (e, false),
            "BREP_WITH_VOIDS" => {
                return Err(IoError::Unsupported {
                    file: self.file.to_path_buf(),
                    at: Place::Entity(solid),
                    kind: "BREP_WITH_VOIDS".into(),
                    role: "solids",
                    face: None,
                });
            }
            _ => {
                e.arity(2)?;
                let outer = e.reference(1, "outer shell")?;
                let s = self.expect(outer, solid, &["CLOSED_SHELL", "ORIENTED_CLOSED_SHELL"])?;
                if s.name() == "ORIENTED_CLOSED_SHELL" {
                    s.arity(4)?;
                    let inner = s.reference(2, "closed shell")?;
                    (self.expect(inner, s.id, &["CLOSED_SHELL"])?, !s.logical(3, "orientation")?)
                } else {
                    (s, false)
                }
            }
        };
        shell.arity(2)?;
        Ok((shell.id, shell.references(1, "faces")?, flip))
    }

    fn face(&self, id: u64, from: u64, flip: bool) -> Result<BrepFace, IoError> {
        let e = self.expect(id, from, &["ADVANCED_FACE", "FACE_SURFACE", "ORIENTED_FACE"])?;
        if e.name() == "ORIENTED_FACE" {
            e.arity(4)?;
            let inner = e.reference(2, "face")?;
            let orientation = e.logical(3, "orientation")?;
            let inner_e = self.expect(inner, id, &["ADVANCED_FACE", "FACE_SURFACE"])?;
            return self.face(inner_e.id, id, flip == orientation);
        }
        e.arity(4)?;
        let bounds = e.references(1, "bounds")?;
        let surface_id = e.reference(2, "face geometry")?;
        let same_sense = e.logical(3, "same_sense")? != flip;
        let surface = self.surface(surface_id, id, same_sense)?;
        let mut loops = Vec::with_capacity(bounds.len());
        for b in bounds {
            if let Some(mut lp) = self.bound(b, id)? {
                if flip {
                    reverse_loop(&mut lp);
                }
                loops.push(lp);
            }
        }
        if let Surface::Plane { normal, .. } = surface {
            if loops.is_empty() {
                return Err(self.syntax(id, format!("{}: a planar face needs at least one edge loop", e.name())));
            }
            orient_planar_loops(&mut loops, normal);
        }
        Ok(BrepFace { source: FaceSource::Step { entity: id }, surface, loops })
    }

    fn surface(&self, id: u64, face: u64, same_sense: bool) -> Result<Surface, IoError> {
        let (entity, inst) = self.simple(id, face)?;
        match entity {
            Some(e) if e.name() == "PLANE" => {
                e.arity(2)?;
                let (point, z) = self.placement(e.reference(1, "position")?, id)?;
                Ok(Surface::Plane { point, normal: if same_sense { z } else { -z } })
            }
            Some(e) if e.name() == "CYLINDRICAL_SURFACE" => {
                e.arity(3)?;
                let (point, axis) = self.placement(e.reference(1, "position")?, id)?;
                let radius = self.length(e, 2, "radius")?;
                Ok(Surface::Cylinder { point, axis, radius, convex: same_sense })
            }
            _ => Err(IoError::Unsupported {
                file: self.file.to_path_buf(),
                at: Place::Entity(id),
                kind: inst.type_name(),
                role: "faces",
                face: Some(face),
            }),
        }
    }

    /// A positive length argument, scaled to mm.
    pub(super) fn length(&self, e: Entity<'_>, i: usize, what: &'static str) -> Result<f64, IoError> {
        let value = check_coordinate(e.number(i, what)? * self.scale, self.file, || Place::Entity(e.id))?;
        if value > 0.0 {
            Ok(value)
        } else {
            Err(IoError::NotPositive { file: self.file.to_path_buf(), at: Place::Entity(e.id), what, value })
        }
    }

    /// A bound's loop, oriented by the bound's flag; `None` for a vertex loop.
    fn bound(&self, id: u64, face: u64) -> Result<Option<Vec<Segment>>, IoError> {
        let e = self.expect(id, face, &["FACE_OUTER_BOUND", "FACE_BOUND"])?;
        e.arity(3)?;
        let loop_id = e.reference(1, "bound")?;
        let orientation = e.logical(2, "orientation")?;
        let mut lp = match self.edge_loop(loop_id, id, face)? {
            Some(lp) => lp,
            None => return Ok(None),
        };
        if !orientation {
            reverse_loop(&mut lp);
        }
        Ok(Some(lp))
    }

    fn edge_loop(&self, id: u64, from: u64, face: u64) -> Result<Option<Vec<Segment>>, IoError> {
        let (entity, inst) = self.simple(id, from)?;
        let unsupported = || IoError::Unsupported {
            file: self.file.to_path_buf(),
            at: Place::Entity(id),
            kind: inst.type_name(),
            role: "loops",
            face: Some(face),
        };
        let e = entity.ok_or_else(unsupported)?;
        match e.name() {
            "VERTEX_LOOP" => Ok(None),
            "POLY_LOOP" => {
                e.arity(2)?;
                let points = e
                    .references(1, "polygon")?
                    .into_iter()
                    .map(|p| self.point(p, id))
                    .collect::<Result<Vec<_>, _>>()?;
                let n = points.len();
                Ok(Some(
                    (0..n)
                        .map(|k| Segment::Line { start: points[k], end: points[(k + 1) % n] })
                        .filter(|s| s.start() != s.end())
                        .collect(),
                ))
            }
            "EDGE_LOOP" => {
                e.arity(2)?;
                let edges = e.references(1, "edge list")?;
                let mut pieces = Vec::with_capacity(edges.len());
                for edge in edges {
                    pieces.push(self.oriented_edge(edge, id, face)?);
                }
                let mut segments = Vec::new();
                for (k, piece) in pieces.iter().enumerate() {
                    let next = &pieces[(k + 1) % pieces.len()];
                    if piece.end_vertex != next.start_vertex && piece.end != next.start {
                        return Err(self.syntax(
                            id,
                            format!(
                                "EDGE_LOOP is not closed: edge #{} ends at vertex #{} but the next edge #{} starts \
                                 at vertex #{}",
                                piece.id, piece.end_vertex, next.id, next.start_vertex
                            ),
                        ));
                    }
                    segments.extend_from_slice(&piece.segments);
                }
                Ok(Some(segments))
            }
            _ => Err(unsupported()),
        }
    }

    fn oriented_edge(&self, id: u64, from: u64, face: u64) -> Result<EdgePiece, IoError> {
        let e = self.expect(id, from, &["ORIENTED_EDGE"])?;
        e.arity(5)?;
        let edge = e.reference(3, "edge element")?;
        let orientation = e.logical(4, "orientation")?;
        let mut piece = self.edge_curve(edge, id, face)?;
        piece.id = id;
        if !orientation {
            reverse_loop(&mut piece.segments);
            std::mem::swap(&mut piece.start_vertex, &mut piece.end_vertex);
            std::mem::swap(&mut piece.start, &mut piece.end);
        }
        Ok(piece)
    }

    /// An `EDGE_CURVE` as segments from its start vertex to its end vertex.
    fn edge_curve(&self, id: u64, from: u64, face: u64) -> Result<EdgePiece, IoError> {
        let e = self.expect(id, from, &["EDGE_CURVE"])?;
        e.arity(5)?;
        let start_vertex = e.reference(1, "edge start")?;
        let end_vertex = e.reference(2, "edge end")?;
        let mut curve = e.reference(3, "edge geometry")?;
        let same_sense = e.logical(4, "same_sense")?;
        let start = self.vertex(start_vertex, id)?;
        let end = self.vertex(end_vertex, id)?;
        let mut referrer = id;
        let mut depth = 0;
        let segments = loop {
            let (entity, inst) = self.simple(curve, referrer)?;
            let unsupported = |kind: String| IoError::Unsupported {
                file: self.file.to_path_buf(),
                at: Place::Entity(curve),
                kind,
                role: "edges",
                face: Some(face),
            };
            let Some(c) = entity else { return Err(unsupported(inst.type_name())) };
            match c.name() {
                "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE" => {
                    depth += 1;
                    if depth > MAX_CHAIN {
                        return Err(self.syntax(curve, format!("curves nested more than {MAX_CHAIN} deep")));
                    }
                    c.arity(4)?;
                    referrer = curve;
                    curve = c.reference(1, "curve_3d")?;
                }
                "LINE" => {
                    c.arity(3)?;
                    break if start == end { Vec::new() } else { vec![Segment::Line { start, end }] };
                }
                "CIRCLE" => {
                    c.arity(3)?;
                    let (center, axis) = self.placement(c.reference(1, "position")?, curve)?;
                    let radius = self.length(c, 2, "radius")?;
                    let axis = if same_sense { axis } else { -axis };
                    break vec![Segment::Arc { center, axis, radius, start, end }];
                }
                "B_SPLINE_CURVE_WITH_KNOTS" | "POLYLINE" => {
                    let points = if c.name() == "POLYLINE" {
                        c.arity(2)?;
                        c.references(1, "points")?
                    } else {
                        c.arity(9)?;
                        let degree = c.integer(1, "degree")?;
                        if degree != 1 {
                            return Err(unsupported(format!("B_SPLINE_CURVE_WITH_KNOTS of degree {degree}")));
                        }
                        c.references(2, "control points")?
                    };
                    if points.len() < 2 {
                        return Err(c.error(format!("{} needs at least 2 points, got {}", c.name(), points.len())));
                    }
                    let mut pts = points.iter().map(|&p| self.point(p, curve)).collect::<Result<Vec<_>, _>>()?;
                    if !same_sense {
                        pts.reverse();
                    }
                    let last = pts.len() - 1;
                    pts[0] = start;
                    pts[last] = end;
                    break pts
                        .windows(2)
                        .filter(|w| w[0] != w[1])
                        .map(|w| Segment::Line { start: w[0], end: w[1] })
                        .collect();
                }
                other => return Err(unsupported(other.to_string())),
            }
        };
        Ok(EdgePiece { id, start_vertex, end_vertex, start, end, segments })
    }

    pub(super) fn vertex(&self, id: u64, from: u64) -> Result<DVec3, IoError> {
        let e = self.expect(id, from, &["VERTEX_POINT"])?;
        e.arity(2)?;
        self.point(e.reference(1, "vertex geometry")?, id)
    }

    /// A `CARTESIAN_POINT` in mm.
    pub(super) fn point(&self, id: u64, from: u64) -> Result<DVec3, IoError> {
        let e = self.expect(id, from, &["CARTESIAN_POINT"])?;
        e.arity(2)?;
        let coords = e.list(1, "coordinates")?;
        if coords.len() != 3 {
            return Err(e.error(format!("CARTESIAN_POINT needs 3 coordinates, got {}", coords.len())));
        }
        let mut p = [0.0; 3];
        for (k, c) in coords.iter().enumerate() {
            let raw = number(c).ok_or_else(|| e.wrong(1, "coordinates", "a list of numbers", c))?;
            p[k] = check_coordinate(raw * self.scale, self.file, || Place::Entity(id))?;
        }
        Ok(DVec3::from_array(p))
    }

    /// A `DIRECTION` as a unit vector.
    pub(super) fn direction(&self, id: u64, from: u64) -> Result<DVec3, IoError> {
        let e = self.expect(id, from, &["DIRECTION"])?;
        e.arity(2)?;
        let ratios = e.list(1, "direction ratios")?;
        if ratios.len() != 3 {
            return Err(e.error(format!("DIRECTION needs 3 ratios, got {}", ratios.len())));
        }
        let mut d = [0.0; 3];
        for (k, c) in ratios.iter().enumerate() {
            d[k] = number(c).ok_or_else(|| e.wrong(1, "direction ratios", "a list of numbers", c))?;
        }
        let v = DVec3::from_array(d);
        let len = v.length();
        if len.is_finite() && len > 0.0 {
            Ok(v / len)
        } else {
            Err(e.error(format!("DIRECTION ({}, {}, {}) has no direction", d[0], d[1], d[2])))
        }
    }

    /// An `AXIS2_PLACEMENT_3D`: its location (mm) and unit z axis (`$`: +z).
    fn placement(&self, id: u64, from: u64) -> Result<(DVec3, DVec3), IoError> {
        let frame = self.frame(id, from)?;
        Ok((frame.origin, frame.z))
    }

    /// An `AXIS2_PLACEMENT_3D` as a frame: location (mm), z axis (`$`: +z) and reference direction (`$`: any).
    pub(super) fn frame(&self, id: u64, from: u64) -> Result<Frame, IoError> {
        let e = self.expect(id, from, &["AXIS2_PLACEMENT_3D"])?;
        e.arity(4)?;
        let location = self.point(e.reference(1, "location")?, id)?;
        let axis = match e.arg(2)? {
            Value::Unset => DVec3::Z,
            Value::Ref(d) => self.direction(*d, id)?,
            other => return Err(e.wrong(2, "axis", "a reference or $", other)),
        };
        let reference = match e.arg(3)? {
            Value::Unset => None,
            Value::Ref(d) => Some(self.direction(*d, id)?),
            other => return Err(e.wrong(3, "ref_direction", "a reference or $", other)),
        };
        Ok(Frame::new(location, axis, reference))
    }
}

/// An oriented edge's segments from its start to its end, and its end vertices.
struct EdgePiece {
    /// The entity (the `ORIENTED_EDGE` once oriented).
    id: u64,
    start_vertex: u64,
    end_vertex: u64,
    start: DVec3,
    end: DVec3,
    segments: Vec<Segment>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn signed_area_of_a_square_with_a_rounded_corner_and_of_circles() {
        let n = DVec3::Z;
        let l = |a: [f64; 2], b: [f64; 2]| Segment::Line {
            start: DVec3::new(a[0], a[1], 0.0),
            end: DVec3::new(b[0], b[1], 0.0),
        };
        // Unit square whose (1,1) corner is replaced by a quarter circle of radius 0.5 about (0.5, 0.5).
        let arc = Segment::Arc {
            center: DVec3::new(0.5, 0.5, 0.0),
            axis: n,
            radius: 0.5,
            start: DVec3::new(1.0, 0.5, 0.0),
            end: DVec3::new(0.5, 1.0, 0.0),
        };
        let lp = vec![
            l([0.0, 0.0], [1.0, 0.0]),
            l([1.0, 0.0], [1.0, 0.5]),
            arc,
            l([0.5, 1.0], [0.0, 1.0]),
            l([0.0, 1.0], [0.0, 0.0]),
        ];
        let want = 1.0 - 0.25 + PI * 0.25 / 4.0;
        assert!((loop_area(&lp, n) - want).abs() < 1e-12);
        let mut rev = lp.clone();
        reverse_loop(&mut rev);
        assert!((loop_area(&rev, n) + want).abs() < 1e-12);
        let p = DVec3::new(3.0, 0.0, 0.0);
        let circle = Segment::Arc { center: DVec3::ZERO, axis: -n, radius: 3.0, start: p, end: p };
        assert!((loop_area(&[circle], n) + 9.0 * PI).abs() < 1e-12);
    }

    #[test]
    fn the_largest_loop_becomes_the_outer_one_counter_clockwise() {
        let n = DVec3::Z;
        let square = |s: f64| {
            let c = [[0.0, 0.0], [s, 0.0], [s, s], [0.0, s]];
            (0..4)
                .map(|k| Segment::Line {
                    start: DVec3::new(c[k][0], c[k][1], 0.0),
                    end: DVec3::new(c[(k + 1) % 4][0], c[(k + 1) % 4][1], 0.0),
                })
                .collect::<Vec<_>>()
        };
        let mut hole = square(1.0);
        let mut outer = square(5.0);
        reverse_loop(&mut outer);
        reverse_loop(&mut hole);
        let mut loops = vec![square(1.0), outer, hole];
        orient_planar_loops(&mut loops, n);
        assert!((loop_area(&loops[0], n) - 25.0).abs() < 1e-12);
        assert!((loop_area(&loops[1], n) + 1.0).abs() < 1e-12);
        assert!((loop_area(&loops[2], n) + 1.0).abs() < 1e-12);
    }

    #[test]
    fn si_prefixes_in_millimetres() {
        assert_eq!(si_prefix_mm("MILLI"), Some(1.0));
        assert_eq!(si_prefix_mm("CENTI"), Some(10.0));
        assert_eq!(si_prefix_mm("KILO"), Some(1e6));
        assert!((si_prefix_mm("MICRO").unwrap_or(0.0) - 1e-3).abs() < 1e-18);
        assert_eq!(si_prefix_mm("BOGUS"), None);
    }
}
