//! The floor of a stage: the stack's footprint, the floor polygon clipped to it (stage 1's floor), and stage 1's
//! floor-side contacts renumbered as sides of the plan's floor.

use crate::request::FloorVolume;
use crate::search::Contact;
use glam::DVec2;
use stackplan_geom::{Part, Pose};

/// The floor polygon clipped to a rectangle (Sutherland-Hodgman; both convex, so the result is convex).
pub(crate) fn clip_to_rectangle(poly: &[DVec2], lo: DVec2, hi: DVec2) -> Vec<DVec2> {
    let mut out = poly.to_vec();
    let edges: [(DVec2, f64); 4] = [(DVec2::X, hi.x), (DVec2::NEG_X, -lo.x), (DVec2::Y, hi.y), (DVec2::NEG_Y, -lo.y)];
    for (n, d) in edges {
        if out.is_empty() {
            break;
        }
        let input = std::mem::take(&mut out);
        for k in 0..input.len() {
            let (a, b) = (input[k], input[(k + 1) % input.len()]);
            let (da, db) = (n.dot(a) - d, n.dot(b) - d);
            if da <= 0.0 {
                out.push(a);
            }
            if (da < 0.0) != (db < 0.0) && da != db {
                // on the rectangle's side exactly (`d n` is `lo` or `hi`): interpolation leaves it an ulp off, and a
                // footprint that only grew must contain the last one (the carried stage-1 frontier's test)
                let mut cut = a + (b - a) * (da / (da - db));
                if n.x != 0.0 {
                    cut.x = d * n.x;
                } else {
                    cut.y = d * n.y;
                }
                out.push(cut);
            }
        }
    }
    out
}

/// `contacts` found on the floor `searched` (stage 1's clipped region) with their `floor_side` contacts renumbered
/// as sides of `floor`, the plan's: a side of `searched` on the line of a side of `floor` (parallel outward normals,
/// offsets within `tol`) is that side; any other side of `searched` is no wall, and its contact is dropped. O(contacts
/// x sides).
pub(super) fn sides_of_floor(
    contacts: &[Contact],
    searched: &FloorVolume,
    floor: &FloorVolume,
    tol: f64,
) -> Vec<Contact> {
    let (searched_sides, floor_sides) = (searched.side_planes(), floor.side_planes());
    let mut out: Vec<Contact> = Vec::with_capacity(contacts.len());
    for contact in contacts {
        let contact = match *contact {
            Contact::FloorSide { side } => {
                let Some(&(n, d)) = searched_sides.get(side as usize) else { continue };
                let on_line = floor_sides.iter().position(|&(m, e)| (n - m).length() <= 1e-9 && (d - e).abs() <= tol);
                match on_line {
                    Some(k) => Contact::FloorSide { side: k as u32 },
                    None => continue,
                }
            }
            ref other => other.clone(),
        };
        if !out.contains(&contact) {
            out.push(contact);
        }
    }
    out
}

/// The xy bounding rectangle of the placed parts.
pub(super) fn footprint(part: &Part, placed: &[Pose]) -> (DVec2, DVec2) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in placed {
        for v in part.all_vertices() {
            let w = p.apply(v).truncate();
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Complex plan's footprint at parts 9 and 10 (`w 0.9`): interpolated cuts left corners an ulp off the
    /// rectangle (-270.99999999999994 beside -271), so the grown footprint did not contain the last one exactly and
    /// the carried stage-1 frontier was dropped (6 800 nodes searched again from the roots).
    #[test]
    fn clipped_footprints_have_their_corners_on_the_rectangle_and_contain_the_smaller_ones() {
        let floor = FloorVolume::rectangle(-501.5, -501.5, 501.5, 501.5, 1212.0).polygon;
        let lo = DVec2::new(-271.0, -237.00000000000006);
        let small = clip_to_rectangle(&floor, lo, DVec2::new(262.0, 274.00000000000006));
        let grown = clip_to_rectangle(&floor, lo, DVec2::new(271.0, 274.00000000000006));
        for (poly, hi) in [(&small, 262.0), (&grown, 271.0)] {
            assert_eq!(poly.len(), 4);
            for c in poly.iter() {
                assert!(c.x == lo.x || c.x == hi, "{c:?}");
                assert!(c.y == lo.y || c.y == 274.00000000000006, "{c:?}");
            }
        }
        let sides = crate::request::polygon_side_planes(&grown);
        assert!(small.iter().all(|&c| sides.iter().all(|&(n, d)| n.dot(c) <= d)), "{small:?} not inside {grown:?}");
        // a floor that is no rectangle: the cuts lie on the rectangle's sides, its own corners stay
        let hexagon: Vec<DVec2> = (0..6)
            .map(|k| {
                let a = std::f64::consts::PI / 3.0 * k as f64 + 0.1;
                DVec2::new(500.0 * a.cos(), 500.0 * a.sin())
            })
            .collect();
        let cut = clip_to_rectangle(&hexagon, DVec2::new(-301.3, -299.7), DVec2::new(299.9, 300.1));
        for c in &cut {
            let on_side = c.x == -301.3 || c.x == 299.9 || c.y == -299.7 || c.y == 300.1;
            assert!(on_side || hexagon.contains(c), "{c:?}");
        }
    }

    #[test]
    fn stage_one_floor_sides_are_renumbered_or_dropped() {
        let floor = FloorVolume::rectangle(0.0, 0.0, 100.0, 50.0, 10.0);
        // the footprint clipped at x <= 40: its sides 0 (y = 0), 2 (y = 50) and 3 (x = 0) lie on the floor's sides 0,
        // 2 and 3; its side 1 (x = 40) is no wall
        let searched = FloorVolume {
            polygon: clip_to_rectangle(&floor.polygon, DVec2::new(-5.0, -5.0), DVec2::new(40.0, 60.0)),
            height: 10.0,
        };
        assert_eq!(searched.polygon.len(), 4);
        let side = |side: u32| Contact::FloorSide { side };
        let stack = Contact::Stack { our_component: 0, stack_part: 0, stack_component: 1, face_kind: "x".into() };
        let found = [Contact::Floor, side(1), stack.clone(), side(0), side(3)];
        assert_eq!(searched.polygon, [(0.0, 0.0), (40.0, 0.0), (40.0, 50.0), (0.0, 50.0)].map(DVec2::from));
        let expected = [Contact::Floor, stack, side(0), side(3)];
        assert_eq!(sides_of_floor(&found, &searched, &floor, 1e-9), expected);
    }

    #[test]
    fn clipping_keeps_the_convex_intersection() {
        let square = [DVec2::ZERO, DVec2::new(4.0, 0.0), DVec2::new(4.0, 4.0), DVec2::new(0.0, 4.0)];
        let c = clip_to_rectangle(&square, DVec2::new(1.0, -1.0), DVec2::new(2.0, 5.0));
        let area: f64 = (0..c.len()).map(|k| c[k].perp_dot(c[(k + 1) % c.len()])).sum::<f64>() / 2.0;
        assert!((area - 4.0).abs() < 1e-12);
        assert!(clip_to_rectangle(&square, DVec2::new(5.0, 5.0), DVec2::new(6.0, 6.0)).is_empty());
    }
}
