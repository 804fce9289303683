//! Unit tests of the pictures: projections, label placement and the figures drawn.
use super::*;
use stackplan_geom::convex_hull;

fn cube_at(o: DVec3) -> ConvexPolytope {
    let pts: Vec<DVec3> =
        (0..8).map(|i| o + DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64)).collect();
    convex_hull(&pts).expect("cube").polytope
}

fn two_cubes() -> Scene {
    Scene {
        solids: vec![
            Solid { polytope: cube_at(DVec3::ZERO), color: part_color(0), part: 0 },
            Solid { polytope: cube_at(DVec3::new(0.0, 0.0, 1.0)), color: part_color(1), part: 1 },
        ],
        markers: vec![Marker { position: DVec3::splat(0.5), color: [200, 0, 0] }],
        floor: vec![DVec3::new(-1.0, -1.0, 0.0), DVec3::new(2.0, -1.0, 0.0), DVec3::new(2.0, 2.0, 0.0)],
        title: "two cubes <test>".into(),
        labels: vec![(1, DVec3::splat(0.5)), (2, DVec3::new(0.5, 0.5, 1.5))],
        legend: parts_legend(true),
    }
}

fn decode(png: &[u8]) -> tiny_skia::Pixmap {
    tiny_skia::Pixmap::decode_png(png).expect("decodes")
}

#[test]
fn pictures_contain_every_visible_face() {
    let scene = two_cubes();
    let bare = Scene { labels: Vec::new(), legend: Vec::new(), ..two_cubes() };
    // isometric: 3 faces per cube; top: 1 per cube (the upward face); side: 1 per cube
    assert_eq!(svg(&bare).matches("stroke-linejoin").count(), 2 * 3 + 2 + 2);
    let s = svg(&scene);
    assert!(s.contains("&lt;test&gt;"));
    assert_eq!(s.matches(">2</text>").count(), 3, "part 2 numbered in each view");
    let p = png(&scene, 1.0).expect("png");
    assert_eq!(&p[1..4], b"PNG");
}

/// Two boxes side by side as one part (a face split into two convex pieces): their shared edge on top is a seam,
/// drawn in the face's colour; as two parts it is an outline. Seen from the top, at the middle of that edge.
#[test]
fn outlines_skip_the_seams_of_a_decomposition() {
    let boxes = |second_part: usize| Scene {
        solids: vec![
            Solid { polytope: cube_at(DVec3::ZERO), color: part_color(0), part: 0 },
            Solid { polytope: cube_at(DVec3::X), color: part_color(0), part: second_part },
        ],
        ..Scene::default()
    };
    let seams_of = |scene: &Scene| seams(scene).iter().flatten().flatten().filter(|s| **s).count();
    // the shared edges of the top, bottom, front and back faces (the glued side faces have opposite normals)
    assert_eq!(seams_of(&boxes(0)), 2 * 4);
    assert_eq!(seams_of(&boxes(1)), 0);
    let top = View { name: "top", toward_viewer: DVec3::Z, up: DVec3::Y };
    let pixel_on_the_shared_edge = |scene: &Scene| {
        let figure = Figure {
            title: String::new(),
            legend: Vec::new(),
            panels: vec![FigurePanel { scene, view: top, caption: String::new() }],
            columns: 1,
            cell: (200.0, 120.0),
            common_scale: false,
        };
        let at = figure.placements();
        let p = at[0].to_screen(DVec3::new(1.0, 0.5, 1.0));
        let image = decode(&figure_png(&figure, 1.0).expect("png"));
        let c = image.pixel(p.x.round() as u32, p.y.round() as u32).expect("inside");
        [c.red(), c.green(), c.blue()]
    };
    let fill = shade(part_color(0), DVec3::Z);
    assert_eq!(pixel_on_the_shared_edge(&boxes(0)), fill, "a seam is drawn in the face's colour");
    let outlined = pixel_on_the_shared_edge(&boxes(1));
    assert!(outlined.iter().zip(fill).all(|(o, f)| *o < f), "{outlined:?} is the outline, darker than {fill:?}");
    // the SVG: one face with a seam gets its outline as a path of the other three edges
    let s = svg(&boxes(0));
    assert!(s.contains(r##"fill="none" stroke="#222222""##), "{s}");
}

/// The PNG writes text with the bundled font: a title in black appears where it is written (dark pixels in its
/// line, none above it), and its width is the font's measure of it.
#[test]
fn png_text_is_drawn_in_the_bundled_font() {
    assert!(font().is_some(), "the bundled font parses");
    let mut canvas = PngCanvas { pixmap: tiny_skia::Pixmap::new(200, 40).expect("pixmap"), scale: 1.0 };
    canvas.pixmap.fill(tiny_skia::Color::WHITE);
    let style = TextStyle { size: 16.0, anchor: Anchor::Start, color: [0, 0, 0], class: None };
    canvas.text(DVec2::new(10.0, 30.0), "Stack of 15", style);
    let dark = |x0: u32, x1: u32, y0: u32, y1: u32| {
        (x0..x1)
            .flat_map(|x| (y0..y1).map(move |y| (x, y)))
            .filter(|&(x, y)| canvas.pixmap.pixel(x, y).expect("inside").red() < 128)
            .count()
    };
    let width = text_width("Stack of 15", 16.0);
    assert!((70.0..110.0).contains(&width), "{width}");
    assert!(dark(10, 10 + width.ceil() as u32, 17, 31) > 100, "the glyphs are drawn");
    assert_eq!(dark(0, 200, 0, 14), 0, "nothing above the capitals");
    assert_eq!(dark(12 + width.ceil() as u32, 200, 0, 40), 0, "nothing past the text's width");
    // the widths of digits: "10" is two digits wide, and every digit has the same advance
    assert!((text_width("10", 11.0) - 2.0 * text_width("8", 11.0)).abs() < 1e-9);
}

/// Fifteen labels at one point (a nested stack's c.g.s seen from above) get boxes that do not overlap, each joined
/// to its c.g. by a leader line except the first, which sits above it; the SVG and the PNG draw them.
#[test]
fn labels_at_one_point_are_moved_apart() {
    let mut scene = two_cubes();
    scene.labels = (1..=15).map(|n| (n, DVec3::new(0.5, 0.5, 1.0 + 1e-5 * n as f64))).collect();
    let figure = three_views(&scene);
    let boxes = label_layout(&figure);
    assert_eq!(boxes.len(), 45);
    for (a, b) in boxes.iter().zip(boxes.iter().skip(1)) {
        assert!(a.panel < b.panel || a.number < b.number);
    }
    for (k, a) in boxes.iter().enumerate() {
        for b in &boxes[k + 1..] {
            assert!(a.panel != b.panel || !a.overlaps(b), "{a:?} {b:?}");
        }
        let cell = figure.cell_origin(a.panel);
        assert!(a.min.cmpge(cell).all() && a.max.cmple(cell + DVec2::new(360.0, 340.0)).all(), "{a:?}");
    }
    assert!(boxes.iter().filter(|b| b.number == 1).all(LabelBox::at_anchor));
    assert!(boxes.iter().filter(|b| b.number > 1).all(|b| !b.at_anchor()));
    let s = svg(&scene);
    assert_eq!(s.matches(r#"<text class="label""#).count(), 45);
    let image = decode(&png(&scene, 2.0).expect("png"));
    for b in &boxes {
        // the box's outline, drawn in the leader colour, at the middle of its top edge
        let p = image.pixel((b.min.x + b.max.x) as u32, (2.0 * b.min.y).floor() as u32).expect("inside");
        assert!(p.red() < 200, "{b:?}: {p:?}");
    }
}

#[test]
fn common_scale_puts_every_panel_on_one_floor_line() {
    let low = two_cubes();
    let mut tall = two_cubes();
    tall.solids.push(Solid { polytope: cube_at(DVec3::new(0.0, 0.0, 2.0)), color: part_color(2), part: 2 });
    let figure = Figure {
        title: String::new(),
        legend: Vec::new(),
        panels: vec![
            FigurePanel { scene: &low, view: ISOMETRIC, caption: "n = 2".into() },
            FigurePanel { scene: &tall, view: ISOMETRIC, caption: "n = 3".into() },
        ],
        columns: 2,
        cell: (200.0, 200.0),
        common_scale: true,
    };
    let at = figure.placements();
    assert_eq!(at[0].scale, at[1].scale);
    let floor_corner = DVec3::new(-1.0, -1.0, 0.0);
    assert!((at[0].to_screen(floor_corner).y - at[1].to_screen(floor_corner).y).abs() < 1e-9);
    let png = figure_png(&figure, 1.0).expect("png");
    let image = decode(&png);
    assert_eq!((image.width(), image.height()), (400, (TITLE + 200.0 + CAPTION) as u32));
}
