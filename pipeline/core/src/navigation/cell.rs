//! Which landmark's Voronoi cell the rover is in, from one panorama's range order (000 §VII-B
//! step 4: a leg ends when the rover "enters its Voronoi cell, as detected by the relative
//! range orderings of observed landmarks").
//!
//! The rover is in landmark `L`'s cell when `L` is the nearest landmark. A partial range order
//! may not say which one is: it is *certainly* `L`'s cell when `L` is known nearer than every
//! other visible landmark, and *possibly* the cell of each landmark no other is known to be
//! nearer than (seed digest A.6, item 4). Only visible landmarks are compared: a hidden one
//! could be nearer still.

use crate::map::LandmarkId;
use crate::measurement::RangeOrder;

/// The cell the rover is in, as far as one panorama tells.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Cell {
    /// Nearer than every other visible landmark.
    Certain(LandmarkId),
    /// Each of these may be the nearest (none is known to be farther than another visible
    /// landmark); at least two.
    Possible(Vec<LandmarkId>),
}

/// The cell of a panorama whose view position `i` shows landmark `visible[i]`, ranged by
/// `order`; `None` when nothing is visible.
pub fn cell_of(visible: &[LandmarkId], order: &RangeOrder) -> Option<Cell> {
    debug_assert_eq!(visible.len(), order.len());
    let n = visible.len();
    let minimal: Vec<usize> = (0..n)
        .filter(|&i| !(0..n).any(|j| order.is_nearer(j, i)))
        .collect();
    // The order is transitively closed: a lone minimal landmark is below every other one.
    match minimal.as_slice() {
        [] => None,
        [only] => Some(Cell::Certain(visible[*only])),
        several => Some(Cell::Possible(
            several.iter().map(|&i| visible[i]).collect(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Point;

    #[test]
    fn a_landmark_below_every_other_is_certain() {
        let order = RangeOrder::total(&[2, 0, 1]).unwrap();
        assert_eq!(cell_of(&[10, 11, 12], &order), Some(Cell::Certain(12)));
        assert_eq!(cell_of(&[], &RangeOrder::unordered(0)), None);
    }

    #[test]
    fn landmarks_no_other_is_known_nearer_than_are_possible() {
        // 0 < 2 and 1 < 2: either 0 or 1 is nearest.
        let order = RangeOrder::from_pairs(3, &[(0, 2), (1, 2)]).unwrap();
        assert_eq!(
            cell_of(&[5, 6, 7], &order),
            Some(Cell::Possible(vec![5, 6]))
        );
        let unordered = RangeOrder::unordered(2);
        assert_eq!(
            cell_of(&[5, 6], &unordered),
            Some(Cell::Possible(vec![5, 6]))
        );
    }

    /// A total range order from true distances puts the rover in the cell of the landmark
    /// nearest to it: checked against geometry at sampled points.
    #[test]
    fn the_certain_cell_is_the_voronoi_cell_of_the_geometry() {
        let landmarks = [
            Point::new(0.0, 0.0),
            Point::new(10.0, 1.0),
            Point::new(4.0, 8.0),
            Point::new(-5.0, 6.0),
        ];
        for x in -8..14 {
            for y in -4..12 {
                let p = Point::new(f64::from(x) + 0.25, f64::from(y) + 0.25);
                let mut nearest_first: Vec<usize> = (0..landmarks.len()).collect();
                nearest_first.sort_by(|&a, &b| {
                    landmarks[a]
                        .distance(p)
                        .total_cmp(&landmarks[b].distance(p))
                });
                let order = RangeOrder::total(&nearest_first).unwrap();
                let ids: Vec<LandmarkId> = (0..landmarks.len() as u32).collect();
                let nearest = (0..landmarks.len())
                    .min_by(|&a, &b| {
                        landmarks[a]
                            .distance(p)
                            .total_cmp(&landmarks[b].distance(p))
                    })
                    .unwrap();
                assert_eq!(cell_of(&ids, &order), Some(Cell::Certain(nearest as u32)));
            }
        }
    }
}
