//! The leg follower of 000 §VII-B steps 4–6: drive toward the first landmark of the route whose
//! Voronoi cell the rover is not yet in, until the range order shows it is the nearest; then the
//! next. It decides from each panorama's observation alone (bearings and range order of the
//! visible landmarks): it has no positions, so it cannot use the world's truth.

use super::cell::{cell_of, Cell};
use super::route::Route;
use crate::map::LandmarkId;
use crate::measurement::StationView;

/// What to do after one panorama.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Drive toward `landmark`, seen at `bearing` (radians, the panorama's frame).
    Toward { landmark: LandmarkId, bearing: f64 },
    /// The rover is in the route's last landmark's cell: the landmark route is done.
    Arrived,
    /// The next landmark of the route is not visible: re-plan or give up.
    TargetLost(LandmarkId),
}

/// Follows one landmark route, leg by leg.
#[derive(Clone, Debug, PartialEq)]
pub struct LegFollower {
    route: Vec<LandmarkId>,
    /// Index into `route` of the current target.
    next: usize,
}

impl LegFollower {
    pub fn new(route: &Route) -> LegFollower {
        LegFollower {
            route: route.landmarks.clone(),
            next: 0,
        }
    }

    /// Ends the leg toward `landmark` if it is the current target: the caller knows the rover
    /// reached it without the range order showing it (a rock near the rover is under a mast
    /// camera's view, where no panorama shows it nearest).
    pub fn reached(&mut self, landmark: LandmarkId) {
        if self.route.get(self.next) == Some(&landmark) {
            self.next += 1;
        }
    }

    /// The command for a panorama showing landmarks `visible` (by view position) as `view`.
    /// A leg ends only when its landmark is *certainly* the nearest (seed digest A.6, 4).
    pub fn step(&mut self, visible: &[LandmarkId], view: &StationView) -> Command {
        let cell = cell_of(visible, &view.order);
        while self.next < self.route.len() && cell == Some(Cell::Certain(self.route[self.next])) {
            self.next += 1;
        }
        // Entering a later landmark's cell directly (a leg cut short) skips the ones before.
        if let Some(Cell::Certain(here)) = cell {
            if let Some(ahead) = self.route[self.next..].iter().position(|&l| l == here) {
                self.next += ahead + 1;
            }
        }
        let Some(&target) = self.route.get(self.next) else {
            return Command::Arrived;
        };
        match visible.iter().position(|&l| l == target) {
            Some(i) => Command::Toward {
                landmark: target,
                bearing: view.bearings[i].angle,
            },
            None => Command::TargetLost(target),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::{Bearing, RangeOrder};

    fn view(bearings: &[f64], nearest_first: &[usize]) -> StationView {
        StationView::new(
            bearings.iter().map(|&a| Bearing::exact(a)).collect(),
            RangeOrder::total(nearest_first).unwrap(),
        )
        .unwrap()
    }

    fn route(landmarks: &[LandmarkId]) -> Route {
        Route {
            landmarks: landmarks.to_vec(),
            cost: landmarks.len().saturating_sub(1) as f64,
            uncertain_edges: 0,
        }
    }

    #[test]
    fn legs_end_when_their_landmark_is_nearest() {
        let mut follower = LegFollower::new(&route(&[7, 8, 9]));
        // In 7's cell: head for 8.
        let at_start = view(&[0.1, 1.0, 2.0], &[0, 1, 2]);
        assert_eq!(
            follower.step(&[7, 8, 9], &at_start),
            Command::Toward {
                landmark: 8,
                bearing: 1.0
            }
        );
        // 8 nearest now: head for 9, which the panorama lists first.
        let later = view(&[2.5, 0.3, 1.2], &[1, 0, 2]);
        assert_eq!(
            follower.step(&[9, 8, 7], &later),
            Command::Toward {
                landmark: 9,
                bearing: 2.5
            }
        );
        let done = view(&[2.5, 0.3], &[0, 1]);
        assert_eq!(follower.step(&[9, 8], &done), Command::Arrived);
    }

    #[test]
    fn an_unseen_target_is_reported_and_an_uncertain_cell_ends_no_leg() {
        let mut follower = LegFollower::new(&route(&[1, 2]));
        let unordered = StationView::new(
            vec![Bearing::exact(0.5), Bearing::exact(1.5)],
            RangeOrder::unordered(2),
        )
        .unwrap();
        // Not certainly in 1's cell: 1 stays the target.
        assert_eq!(
            follower.step(&[1, 2], &unordered),
            Command::Toward {
                landmark: 1,
                bearing: 0.5
            }
        );
        let without_two = view(&[0.5], &[0]);
        assert_eq!(follower.step(&[1], &without_two), Command::TargetLost(2));
    }

    #[test]
    fn a_leg_reached_out_of_view_ends_and_only_the_current_one() {
        let mut follower = LegFollower::new(&route(&[1, 2, 3]));
        let far = view(&[0.5, 1.5, 2.5], &[0, 1, 2]);
        // Not the current target: nothing changes.
        follower.reached(2);
        assert_eq!(
            follower.step(&[1, 2, 3], &far),
            Command::Toward {
                landmark: 2,
                bearing: 1.5
            }
        );
        // Landmark 2 is under the camera: its leg ends though the panorama does not show it.
        let without_two = view(&[0.5, 2.5], &[0, 1]);
        assert_eq!(follower.step(&[1, 3], &without_two), Command::TargetLost(2));
        follower.reached(2);
        assert_eq!(
            follower.step(&[1, 3], &without_two),
            Command::Toward {
                landmark: 3,
                bearing: 2.5
            }
        );
        follower.reached(3);
        assert_eq!(follower.step(&[1], &view(&[0.5], &[0])), Command::Arrived);
    }
}
