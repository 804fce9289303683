//! Python bindings of stackplan (`import stackplan`): a thin layer over the facade crate `stackplan` and the command
//! line's library, so that Python and `stackplan` agree by construction.
//!
//! - Options are given as keyword arguments named like the command line's options (`dtheta_deg` for
//!   `--dtheta-deg`) and parsed by the command line's own parser (`stackplan_cli::cmd::batch::plan_args`): same
//!   defaults, same checks, same one-line messages.
//! - Plans are written by the command line's writer (`stackplan_cli::plan_files`): `Plan.to_json()` is `plan.json`
//!   and `Plan.write(dir)` writes the files of `stackplan plan`.
//! - Every error is a `stackplan.StackplanError` (a `ValueError`) carrying the command line's one-line message.
//! - Long calls run on a thread of their own without the GIL; the calling thread waits for it, checking for Ctrl-C
//!   every 50 ms ([`run_detached`]).
//!
//! Arrays cross as nested lists through `numpy.asarray` (numpy is the package's one Python dependency): the parts
//! and stacks here are small, and no array crate is needed.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use serde_json::{Map, Value};
use stackplan::geom::io::{ReadOptions, Units};
use stackplan::geom::{DMat3, Decomposition};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc::RecvTimeoutError;
use std::time::Duration;

pyo3::create_exception!(
    _native,
    StackplanError,
    PyValueError,
    "An error of stackplan, with the command line's one-line message (bad input, an unreadable file, a plan that \
     could not place a single part)."
);

fn error(e: &anyhow::Error) -> PyErr {
    StackplanError::new_err(stackplan_cli::error_text(e))
}

fn message(m: impl Into<String>) -> PyErr {
    StackplanError::new_err(m.into())
}

/// Runs `f` on a thread of its own while the calling thread, without the GIL, waits for it and checks for Ctrl-C
/// (`KeyboardInterrupt` is raised at once; the abandoned computation runs on to its end in the background, bounded by
/// its own limits such as `time_limit`, and its result is dropped: the libraries have no cancellation point).
fn run_detached<T: Send + 'static>(py: Python<'_>, f: impl FnOnce() -> T + Send + 'static) -> PyResult<T> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("stackplan".into())
        .spawn(move || {
            let _ = tx.send(f());
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    let mut rx = rx;
    loop {
        let (received, back) = py.detach(move || (rx.recv_timeout(Duration::from_millis(50)), rx));
        rx = back;
        match received {
            Ok(value) => return Ok(value),
            Err(RecvTimeoutError::Timeout) => py.check_signals()?,
            Err(RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err("internal error: the computation ended without a result"));
            }
        }
    }
}

/// `numpy.asarray(value, dtype)`.
fn numpy_array<'py>(py: Python<'py>, value: impl IntoPyObject<'py>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("numpy")?.getattr("asarray")?.call1((value, dtype))
}

/// Points from an array-like of shape `(n, 3)`; `what` names it in errors.
fn points(py: Python<'_>, value: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    let array =
        numpy_array(py, value, "float64").map_err(|e| message(format!("{what}: not an array of numbers: {e}")))?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(message(format!("{what}: expected an (n, 3) array of points, got shape {shape:?}")));
    }
    array.call_method0("tolist")?.extract()
}

/// Read options of a part file from the keyword arguments of `Part.from_file`.
fn read_options(units: &str, triangulate: bool) -> PyResult<ReadOptions> {
    let units: Units = units.parse().map_err(|e: String| message(format!("units: {e}")))?;
    Ok(ReadOptions { decomposition: decomposition(triangulate), units, ..Default::default() })
}

fn decomposition(triangulate: bool) -> Decomposition {
    stackplan_cli::input::decomposition(triangulate)
}

/// A part from a part JSON text (the reader's checks and messages; `label` names it).
fn part_from_json(text: &str, label: &str) -> anyhow::Result<stackplan::geom::Part> {
    Ok(stackplan::geom::io::json::parse_part_json(text.as_bytes(), Path::new(label), &ReadOptions::default())?)
}

/// A rigid part: a union of convex pieces (mm).
#[pyclass(frozen, module = "stackplan")]
#[derive(Debug, Clone)]
pub struct Part {
    inner: Arc<stackplan::geom::Part>,
}

#[pymethods]
impl Part {
    /// Reads a part file: `.step`/`.stp`, `.stl`, `.obj` or part `.json` (STEP solids and non-convex meshes are
    /// recognised as sheet metal). `units`: the length unit of STL and OBJ files (mm, cm, m or in).
    #[staticmethod]
    #[pyo3(signature = (path, units = "mm", triangulate = false))]
    fn from_file(py: Python<'_>, path: PathBuf, units: &str, triangulate: bool) -> PyResult<Self> {
        let options = read_options(units, triangulate)?;
        let part =
            run_detached(py, move || stackplan::geom::io::read_part(&path, &options))?.map_err(|e| error(&e.into()))?;
        Ok(Self { inner: Arc::new(part) })
    }

    /// A part from its convex pieces: each piece an `(n, 3)` array of points (mm) whose convex hull is the piece.
    #[staticmethod]
    #[pyo3(signature = (pieces, name = "part", density = 1.0))]
    fn from_arrays(py: Python<'_>, pieces: &Bound<'_, PyAny>, name: &str, density: f64) -> PyResult<Self> {
        let mut list = Vec::new();
        for (i, piece) in pieces.try_iter()?.enumerate() {
            list.push(points(py, &piece?, &format!("pieces[{i}]"))?);
        }
        let text = serde_json::json!({ "name": name, "density": density, "convex_pieces": list }).to_string();
        let part = part_from_json(&text, "<arrays>").map_err(|e| error(&e))?;
        Ok(Self { inner: Arc::new(part) })
    }

    /// A built-in example part: channel, triangle, complex, cube, l-corner or block.
    #[staticmethod]
    #[pyo3(signature = (name, triangulate = false))]
    fn example(name: &str, triangulate: bool) -> PyResult<Self> {
        let part = stackplan_cli::input::load_part_spec(&format!("example:{name}"), decomposition(triangulate))
            .map_err(|e| error(&e))?;
        Ok(Self { inner: Arc::new(part) })
    }

    /// The part's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The vertices of each convex piece: a list of `(n, 3)` float arrays (mm).
    #[getter]
    fn pieces<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.inner
            .components()
            .iter()
            .map(|c| numpy_array(py, c.vertices().iter().map(|v| v.to_array()).collect::<Vec<_>>(), "float64"))
            .collect()
    }

    /// The faces of each convex piece as triangles: a list of `(k, 3)` int arrays indexing that piece's vertices
    /// (`pieces[i]`), each convex face fanned, counter-clockwise seen from outside; with `pieces` a mesh per piece for
    /// trimesh or Open3D.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.inner.components().iter().map(|c| triangles_array(py, c)).collect()
    }

    /// Volume of the union of the pieces (mm^3).
    #[getter]
    fn volume(&self) -> f64 {
        self.inner.mass().volume
    }

    /// Mass: density x volume.
    #[getter]
    fn mass(&self) -> f64 {
        self.inner.mass().mass
    }

    /// Centre of gravity `(3,)` (mm).
    #[getter]
    fn center_of_gravity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        numpy_array(py, self.inner.mass().center_of_gravity.to_array(), "float64")
    }

    /// The axis-aligned bounding box `(lo, hi)`, two `(3,)` arrays (mm).
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (lo, hi) = self.inner.aabb();
        Ok((numpy_array(py, lo.to_array(), "float64")?, numpy_array(py, hi.to_array(), "float64")?))
    }

    /// The part as part JSON (convex-pieces form), as `stackplan part export --json` writes it.
    fn to_json(&self) -> String {
        stackplan::geom::io::json::part_json_string(&self.inner)
    }

    fn __repr__(&self) -> String {
        format!(
            "Part(name={:?}, pieces={}, volume={:.6} mm^3)",
            self.inner.name,
            self.inner.components().len(),
            self.inner.mass().volume
        )
    }
}

/// A stacking plan.
#[pyclass(frozen, module = "stackplan")]
#[derive(Debug)]
pub struct Plan {
    part: Arc<stackplan::geom::Part>,
    plan: stackplan::planner::Plan,
    seconds: f64,
}

impl Plan {
    fn text(&self, timings: bool) -> anyhow::Result<String> {
        if timings {
            stackplan_cli::plan_files::plan_document_text(&self.part, &self.plan, self.seconds)
        } else {
            stackplan_cli::plan_files::plan_document_text(
                &self.part,
                &stackplan_cli::plan_files::untimed(&self.plan),
                0.0,
            )
        }
    }
}

#[pymethods]
impl Plan {
    /// The pose of each placed part as an `(n, 4, 4)` float array: world point = `pose[:3, :3] @ p + pose[:3, 3]`.
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let poses: Vec<[[f64; 4]; 4]> = self
            .plan
            .parts
            .iter()
            .map(|p| {
                let (r, t) = (p.rotation, p.position);
                [
                    [r[0][0], r[0][1], r[0][2], t[0]],
                    [r[1][0], r[1][1], r[1][2], t[1]],
                    [r[2][0], r[2][1], r[2][2], t[2]],
                    [0.0, 0.0, 0.0, 1.0],
                ]
            })
            .collect();
        numpy_array(py, poses, "float64")?.call_method1("reshape", ((self.plan.parts.len(), 4, 4),))
    }

    /// The planned part.
    #[getter]
    fn part(&self) -> Part {
        Part { inner: self.part.clone() }
    }

    /// Parts placed.
    #[getter]
    fn placed(&self) -> usize {
        self.plan.parts.len()
    }

    /// Parts asked for.
    #[getter]
    fn count(&self) -> usize {
        self.plan.options.count
    }

    /// Height of the stack's top (mm).
    #[getter]
    fn height(&self) -> f64 {
        self.plan.height
    }

    /// Floor footprint `((x_min, y_min), (x_max, y_max))` (mm).
    #[getter]
    fn footprint(&self) -> ((f64, f64), (f64, f64)) {
        let [[x0, y0], [x1, y1]] = self.plan.footprint;
        ((x0, y0), (x1, y1))
    }

    /// Sum of the parts' cost terms (mm^2).
    #[getter]
    fn total_cost(&self) -> f64 {
        self.plan.total_cost
    }

    /// Why the plan ended early, or `None` when every part was placed.
    #[getter]
    fn stopped(&self) -> Option<String> {
        self.plan.stopped.clone()
    }

    /// Whether the finished stack passed the whole-stack check.
    #[getter]
    fn stack_stable(&self) -> bool {
        self.plan.stack_stable
    }

    /// Planning time (s).
    #[getter]
    fn seconds(&self) -> f64 {
        self.seconds
    }

    /// The plan file's text (`plan.json` of `stackplan plan`). `timings=False`: the timings 0, as `stackplan batch`
    /// writes it, so that the same options give the same text byte for byte.
    #[pyo3(signature = (timings = true))]
    fn to_json(&self, timings: bool) -> PyResult<String> {
        self.text(timings).map_err(|e| error(&e))
    }

    /// Writes the files of `stackplan plan` into `dir` (created if missing): plan.json, stack.svg, stack.png,
    /// build.svg, build.png, stack.glb and report.html, all or none.
    fn write(&self, py: Python<'_>, dir: PathBuf) -> PyResult<()> {
        let (part, plan, seconds) = (self.part.clone(), self.plan.clone(), self.seconds);
        run_detached(py, move || stackplan_cli::plan_files::write_plan_files(&dir, &part, &plan, seconds))?
            .map_err(|e| error(&e))
    }

    fn __repr__(&self) -> String {
        format!(
            "Plan(part={:?}, placed={} of {}, height={:.3} mm, {})",
            self.part.name,
            self.plan.parts.len(),
            self.plan.options.count,
            self.plan.height,
            self.plan.stopped.as_deref().unwrap_or("complete")
        )
    }
}

/// A Python int or float as a JSON number (ints stay ints: `10`, not `10.0`, in messages); a float JSON cannot hold
/// as its text (`NaN`, `inf`).
fn number(value: &Bound<'_, PyAny>) -> Option<Value> {
    if value.extract::<bool>().is_ok() {
        return None;
    }
    if let Ok(i) = value.extract::<i64>() {
        return Some(Value::from(i));
    }
    let x = value.extract::<f64>().ok()?;
    Some(serde_json::Number::from_f64(x).map_or_else(|| Value::String(x.to_string()), Value::Number))
}

/// The keyword arguments as a JSON object (`None` values left out: the command line's default).
fn options_map(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Map<String, Value>> {
    let mut map = Map::new();
    let Some(kwargs) = kwargs else { return Ok(map) };
    for (key, value) in kwargs.iter() {
        let key: String = key.extract()?;
        let json = if value.is_none() {
            continue;
        } else if let Ok(b) = value.extract::<bool>() {
            Value::Bool(b)
        } else if let Some(n) = number(&value) {
            n
        } else if let Ok(s) = value.extract::<String>() {
            Value::String(s)
        } else if value.hasattr("__fspath__")? {
            Value::String(value.extract::<PathBuf>()?.display().to_string())
        } else if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() || value.hasattr("tolist")? {
            let not_numbers = || message(format!("{key}: expected a sequence of numbers"));
            let list = if value.hasattr("tolist")? { value.call_method0("tolist")? } else { value.clone() };
            let mut items = Vec::new();
            for item in list.try_iter().map_err(|_| not_numbers())? {
                items.push(number(&item?).ok_or_else(not_numbers)?);
            }
            // a number JSON cannot hold (NaN, infinity) goes as its text, which the parser reads and the checks reject
            if items.iter().any(Value::is_string) {
                Value::String(
                    items
                        .iter()
                        .map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_string))
                        .collect::<Vec<_>>()
                        .join(","),
                )
            } else {
                Value::Array(items)
            }
        } else {
            return Err(message(format!("{key}: expected a number, a string, a bool or a sequence of numbers")));
        };
        map.insert(key, json);
    }
    Ok(map)
}

/// Plans a stack of `count` copies of `part` (a `Part`, a part file's path or `"example:NAME"`). The keyword
/// arguments are `stackplan plan`'s options (`count`, `w`, `floor`, `height`, `clearance`, `dtheta_deg`, `mu`,
/// `cup_diameter`, `candidates`, `search_partitions`, `grasp_tilt_deg`, `time_limit`, `node_budget`, `triangulate`)
/// with its defaults. Raises `StackplanError` when not even the first part can be placed.
#[pyfunction]
#[pyo3(signature = (part, **options))]
fn plan(py: Python<'_>, part: &Bound<'_, PyAny>, options: Option<&Bound<'_, PyDict>>) -> PyResult<Plan> {
    let mut map = options_map(options)?;
    let given: Option<Arc<stackplan::geom::Part>> = match part.extract::<Part>() {
        Ok(p) => Some(p.inner),
        Err(_) => {
            let spec: PathBuf =
                part.extract().map_err(|_| message("part: expected a Part, a path or \"example:NAME\""))?;
            map.insert("part".into(), Value::String(spec.display().to_string()));
            None
        }
    };
    if given.is_some() && map.contains_key("triangulate") {
        return Err(message("triangulate: give it to Part.from_file or Part.example (the part is already split)"));
    }
    let args = stackplan_cli::cmd::batch::plan_args(&map, None).map_err(message)?;
    let (part, plan, seconds) = run_detached(py, move || -> anyhow::Result<_> {
        stackplan_cli::cmd::plan::check_w("w", args.w)?;
        let part = match given {
            Some(part) => {
                args.planner.check()?;
                part
            }
            None => Arc::new(args.planner.load_part(&args.part)?),
        };
        let options = args.planner.options(&part, args.w)?;
        let (plan, seconds) = stackplan_cli::cmd::plan::run_planner(&part, &options, &mut |_| {})?;
        Ok((part, plan, seconds))
    })?
    .map_err(|e| error(&e))?;
    Ok(Plan { part, plan, seconds })
}

/// The result of `check`: every part's interference, clearance, stability, grasp, insertion and removal.
#[pyclass(frozen, module = "stackplan")]
#[derive(Debug)]
pub struct Report {
    json: Value,
}

#[pymethods]
impl Report {
    /// Whether every check passed for every part.
    #[getter]
    fn ok(&self) -> bool {
        self.json.get("ok").and_then(Value::as_bool).unwrap_or(false)
    }

    /// The report as `stackplan check --json` prints it.
    fn to_json(&self) -> PyResult<String> {
        stackplan_cli::output::json_text(&self.json).map_err(|e| error(&e))
    }

    /// The report as a dict (`json.loads(report.to_json())`).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (self.to_json()?,))
    }

    fn __repr__(&self) -> String {
        let parts = self.json.get("parts").and_then(Value::as_array).map_or(0, Vec::len);
        format!("Report(ok={}, parts={parts})", if self.ok() { "True" } else { "False" })
    }
}

/// A stack file from a `Plan` or a path.
fn stack_file(stack: &Bound<'_, PyAny>) -> PyResult<(stackplan::geom::io::stack::StackFile, PathBuf)> {
    if let Ok(plan) = stack.cast::<Plan>() {
        let plan = plan.get();
        let label = PathBuf::from("<plan>");
        let text = plan.text(true).map_err(|e| error(&e))?;
        let file = stackplan::geom::io::stack::parse_stack(text.as_bytes(), &label, &ReadOptions::default())
            .map_err(|e| error(&e.into()))?;
        return Ok((file, label));
    }
    let path: PathBuf = stack.extract().map_err(|_| message("stack: expected a Plan or the path of a stack file"))?;
    let file = stackplan::geom::io::stack::read_stack(&path).map_err(|e| error(&e.into()))?;
    Ok((file, path))
}

/// Checks a stack (a `Plan`, or the path of a stack or plan file) as `stackplan check` does: a plan is checked with
/// its own friction, clearance, cup and floor volume unless given here.
#[pyfunction]
#[pyo3(signature = (stack, mu = None, clearance = None, cup_diameter = None, grasp_tilt_deg = None, contact_tolerance = None, margin_directions = 8))]
fn check(
    py: Python<'_>,
    stack: &Bound<'_, PyAny>,
    mu: Option<f64>,
    clearance: Option<f64>,
    cup_diameter: Option<f64>,
    grasp_tilt_deg: Option<f64>,
    contact_tolerance: Option<f64>,
    margin_directions: usize,
) -> PyResult<Report> {
    let (file, path) = stack_file(stack)?;
    let args = stackplan_cli::cmd::check::Args {
        stack: path,
        mu,
        clearance,
        cup_diameter,
        grasp_tilt_deg,
        contact_tolerance,
        margin_directions,
        json: true,
    };
    let json = run_detached(py, move || {
        stackplan_cli::cmd::check::check_stack_file(&file, &args).and_then(stackplan_cli::cmd::check::check_json_value)
    })?
    .map_err(|e| error(&e))?;
    Ok(Report { json })
}

/// The translational c-space obstacle of two convex pieces (each an `(n, 3)` array of points whose convex hull is the
/// piece): the positions of piece `a`, turned by `theta_deg` degrees about z, at which it overlaps piece `b`
/// (\[A\] section III). Returns `(vertices, faces)`: an `(m, 3)` float array and a `(k, 3)` int array of triangles
/// (each convex face fanned), counter-clockwise seen from outside.
#[pyfunction]
#[pyo3(signature = (a, b, theta_deg = 0.0))]
fn cspace_obstacle<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    theta_deg: f64,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    if !theta_deg.is_finite() {
        return Err(message(format!("theta_deg must be a finite number of degrees, got {theta_deg}")));
    }
    let piece = |value: &Bound<'py, PyAny>, what: &str| -> PyResult<stackplan::geom::ConvexPolytope> {
        let text = serde_json::json!({ "name": what, "convex_pieces": [points(py, value, what)?] }).to_string();
        let part = part_from_json(&text, &format!("<{what}>")).map_err(|e| error(&e))?;
        Ok(part.components()[0].clone())
    };
    let (a, b) = (piece(a, "a")?, piece(b, "b")?);
    let rotation = DMat3::from_rotation_z(stackplan::geom::pose::radians_mod_turn(theta_deg));
    let obstacle = run_detached(py, move || stackplan::cspace::minkowski::obstacle(&a, rotation, &b))?
        .map_err(|e| error(&e.into()))?;
    let polytope = obstacle.polytope();
    let vertices: Vec<[f64; 3]> = polytope.vertices().iter().map(|v| v.to_array()).collect();
    Ok((numpy_array(py, vertices, "float64")?, triangles_array(py, polytope)?))
}

/// The faces of a convex polytope as a `(k, 3)` int array of triangles (each face fanned from its first corner,
/// counter-clockwise seen from outside).
fn triangles_array<'py>(py: Python<'py>, polytope: &stackplan::geom::ConvexPolytope) -> PyResult<Bound<'py, PyAny>> {
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    for face in polytope.faces() {
        let cycle: Vec<usize> = face.vertices.iter().copied().collect();
        for k in 1..cycle.len().saturating_sub(1) {
            triangles.push([cycle[0], cycle[k], cycle[k + 1]]);
        }
    }
    let n = triangles.len();
    numpy_array(py, triangles, "int64")?.call_method1("reshape", ((n, 3),))
}

/// `json.loads(text of value)`: a JSON value as Python objects.
fn to_python<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (value.to_string(),))
}

/// The best interference-free placements of `part` in `stack` (a `Plan`, or the path of a stack or plan file), as
/// `stackplan place --json` finds them. The keyword arguments are `place`'s options (`floor`, `height`, `w`,
/// `origin`, `target`, `dtheta_deg`, `clearance`, `insertion`, `fixed_z`, `k`, `floor_polygon`) with its defaults.
/// Returns the JSON of `place --json` as a dict: `placements` (best first: `position`, `rotation` rows,
/// `theta_rad`, `theta_deg`, `cost`, `contacts`, ...), `exhausted` and `stats`.
#[pyfunction]
#[pyo3(signature = (part, stack, **options))]
fn place<'py>(
    py: Python<'py>,
    part: &Bound<'py, PyAny>,
    stack: &Bound<'py, PyAny>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let part: Part = part.extract().map_err(|_| message("part: expected a Part"))?;
    let (file, path) = stack_file(stack)?;
    let map = options_map(options)?;
    let positional = [part.inner.name.clone(), format!("--stack={}", path.display())];
    let args: stackplan_cli::cmd::place::Args =
        stackplan_cli::options::command_args(&map, &positional, &["stack", "triangulate"], &["part", "stack"])
            .map_err(message)?;
    let json = run_detached(py, move || {
        stackplan_cli::cmd::place::search(&args, &part.inner, &file)
            .and_then(|result| stackplan_cli::cmd::place::placements_json(&result))
    })?
    .map_err(|e| error(&e))?;
    to_python(py, &json)
}

/// The assembly contact states of `moving` against `fixed` (two `Part`s) within the box `t_min` .. `t_max` on
/// `t = (x, y, z, rx, ry, rz)` (mm and degrees; \[P\] Pan & Schimmels 2004), as `stackplan contacts --json` finds
/// them. Keyword arguments: `offset` (a translation of the fixed part, mm), `seed`, `population`, `generations`.
/// Returns the graph's JSON as a dict.
#[pyfunction]
#[pyo3(signature = (moving, fixed, t_min, t_max, **options))]
fn contacts<'py>(
    py: Python<'py>,
    moving: &Bound<'py, PyAny>,
    fixed: &Bound<'py, PyAny>,
    t_min: &Bound<'py, PyAny>,
    t_max: &Bound<'py, PyAny>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let moving: Part = moving.extract().map_err(|_| message("moving: expected a Part"))?;
    let fixed: Part = fixed.extract().map_err(|_| message("fixed: expected a Part"))?;
    let bounds = PyDict::new(py);
    bounds.set_item("t_min", t_min)?;
    bounds.set_item("t_max", t_max)?;
    let mut map = options_map(Some(&bounds))?;
    map.extend(options_map(options)?);
    let positional = [moving.inner.name.clone(), fixed.inner.name.clone()];
    let args: stackplan_cli::cmd::contacts::Args =
        stackplan_cli::options::command_args(&map, &positional, &["dot", "triangulate"], &["moving", "fixed"])
            .map_err(message)?;
    let json = run_detached(py, move || -> anyhow::Result<Value> {
        let graph = stackplan_cli::cmd::contacts::contact_graph(&args, &moving.inner, (*fixed.inner).clone())?;
        Ok(serde_json::to_value(&graph)?)
    })?
    .map_err(|e| error(&e))?;
    to_python(py, &json)
}

/// The compiled part of the `stackplan` package.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("StackplanError", m.py().get_type::<StackplanError>())?;
    m.add_class::<Part>()?;
    m.add_class::<Plan>()?;
    m.add_class::<Report>()?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(cspace_obstacle, m)?)?;
    m.add_function(wrap_pyfunction!(place, m)?)?;
    m.add_function(wrap_pyfunction!(contacts, m)?)?;
    Ok(())
}
