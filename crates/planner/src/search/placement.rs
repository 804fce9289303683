//! A free optimum as a placement: its pose, cost and the contacts read from the active constraints of its cell.

use super::*;
use crate::cell_qp::QpOptimum;
use crate::obstacles::PlaneOrigin;
use glam::DVec3;
use stackplan_freespace::{Cell, Tag};

impl Search<'_, '_> {
    pub(super) fn placement<const D: usize>(
        &self,
        cell: &Cell<D>,
        optimum: &QpOptimum<D>,
        orientation: usize,
        p: DVec3,
    ) -> Placement {
        let o = &self.orientations[orientation];
        let mut contacts = Vec::new();
        for &j in &optimum.active {
            let contact = match cell.halfspaces()[j].tag {
                Tag::ObstacleFace { obstacle, face } => {
                    let ob = &self.obstacles[obstacle as usize];
                    // a face plane reaches past its face: p touches the obstacle only when it lies on it (the
                    // cells' tolerance; the clearance's growth is part of the planes)
                    if ob.is_searched_elsewhere() || !ob.closure_contains(p, self.tol.linear) {
                        continue;
                    }
                    let sc = &self.scene.components[ob.fixed];
                    // a face of C on the insertion obstacle's boundary below C is a side of the sweep
                    let face_kind = if ob.under_sweep(p, self.tol.linear) {
                        PlaneOrigin::InsertionSide.name()
                    } else {
                        ob.origins[face as usize].name()
                    };
                    if ob.moving_plate.is_some() || ob.fixed_plate.is_some() {
                        // a merged obstacle's face: the pieces of its sides that touch
                        let touching = crate::plates::touching_pieces(
                            self.request,
                            &self.scene,
                            &o.components,
                            ob.moving_plate,
                            ob.moving,
                            ob.fixed_plate,
                            ob.fixed,
                            p,
                            self.request.clearance,
                            self.tol.linear,
                        );
                        for (ours, theirs) in touching {
                            let contact = Contact::Stack {
                                our_component: ours,
                                stack_part: sc.part,
                                stack_component: self.scene.components[theirs].piece,
                                face_kind: face_kind.to_string(),
                            };
                            if !contacts.contains(&contact) {
                                contacts.push(contact);
                            }
                        }
                        continue;
                    }
                    Contact::Stack {
                        our_component: ob.moving,
                        stack_part: sc.part,
                        stack_component: sc.piece,
                        face_kind: face_kind.to_string(),
                    }
                }
                Tag::Floor => Contact::Floor,
                Tag::Ceiling => Contact::Ceiling,
                // a side of the request's floor (a state carried from a smaller floor keeps that floor's sides as
                // bounds of its old cells, which are not walls of this one)
                Tag::FloorSide { side } => {
                    let h = &cell.halfspaces()[j];
                    let wall = self.request.floor.side_planes().get(side as usize).is_some_and(|&(n, d)| {
                        let parallel = (h.normal[0] - n.x).abs() <= 1e-12 && (h.normal[1] - n.y).abs() <= 1e-12;
                        let gap = n.x * p.x + n.y * p.y + o.support(DVec3::new(n.x, n.y, 0.0)) - d;
                        parallel && gap.abs() <= self.tol.linear
                    });
                    if !wall {
                        continue;
                    }
                    Contact::FloorSide { side }
                }
                Tag::ObstacleCut { .. } | Tag::User(_) => continue,
            };
            if !contacts.contains(&contact) {
                contacts.push(contact);
            }
        }
        if D == 2 && (p.z + o.lo.z).abs() <= self.tol.linear {
            contacts.push(Contact::Floor);
        }
        Placement {
            position: p.to_array(),
            rotation: o.rotation.transpose().to_cols_array_2d(),
            theta: o.theta,
            theta_deg: o.theta.to_degrees(),
            resting_pose: o.rest,
            cost: o.quadratic.value(&p.to_array()),
            contacts,
        }
    }
}
