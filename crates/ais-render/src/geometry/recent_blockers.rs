//! What blocked a gather's earlier shadow rays, tried before a traversal.

/// The primitives that blocked a gather's rays (rays that share an origin), for
/// [`super::Geometry::occluded_after`] to try before a traversal: the blocked rays of a gather in a
/// room mostly meet the same few surfaces (walls, a ceiling). Start a new one for each
/// origin: it only saves time, and a fresh one per gather keeps the work independent of the
/// thread count.
#[derive(Clone, Copy, Debug, Default)]
pub struct RecentBlockers {
    /// Blocking primitives in the accelerator's order, the most recently useful first, no
    /// two in the same run of eight triangles.
    pub(super) recent: [u32; RECENT_BLOCKERS],
    /// How many of `recent` are filled.
    len: usize,
    /// Rays blocked by a primitive of `recent` past the first, and rays that tried those
    /// and found none blocking: the past-the-first are tried only while they pay.
    later_hits: u32,
    later_misses: u32,
}

/// How many blockers a gather remembers.
const RECENT_BLOCKERS: usize = 8;

impl RecentBlockers {
    /// How many of the blockers the next ray tries: the first always, the rest while about
    /// one ray in five that tries them is blocked by one. A run's test takes roughly a
    /// fifth of a blocked ray's traversal (about 12 against 60 ns in the rooms' profiles),
    /// so below that rate the tries cost more than they save, as in foliage, where a
    /// blocking leaf rarely blocks another ray. The first few tries are free of the rule.
    pub(super) fn how_many_to_try(&self) -> usize {
        if self.later_misses <= 4 * self.later_hits + 4 {
            self.len
        } else {
            self.len.min(1)
        }
    }

    /// `recent[at]` blocked the ray: it moves to the front.
    pub(super) fn blocked_by(&mut self, at: usize) {
        if at > 0 {
            self.later_hits += 1;
        }
        self.recent[..=at].rotate_right(1);
    }

    /// None of the first `tried` blocked the ray.
    pub(super) fn missed(&mut self, tried: usize) {
        if tried > 1 {
            self.later_misses += 1;
        }
    }

    /// A blocker found by traversal, put at the front (in the place of one that makes the
    /// same test); the oldest drops out when all places are taken.
    pub(super) fn remember(&mut self, index: usize, same_test: impl Fn(usize, usize) -> bool) {
        let known = self.recent[..self.len]
            .iter()
            .position(|&k| same_test(k as usize, index));
        let at = known.unwrap_or_else(|| {
            self.len = (self.len + 1).min(RECENT_BLOCKERS);
            self.len - 1
        });
        self.recent[at] = index as u32;
        self.recent[..=at].rotate_right(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Same test: the same run of eight.
    fn same_run(a: usize, b: usize) -> bool {
        a / 8 == b / 8
    }

    #[test]
    fn the_most_recently_useful_blocker_comes_first_and_the_oldest_drops_out() {
        let mut blockers = RecentBlockers::default();
        for index in 0..RECENT_BLOCKERS + 1 {
            blockers.remember(index * 8, same_run);
        }
        assert_eq!(blockers.len, RECENT_BLOCKERS);
        assert_eq!(blockers.recent[0], (RECENT_BLOCKERS * 8) as u32);
        assert!(!blockers.recent.contains(&0), "the oldest is gone");
        // A primitive of a run already there takes that run's place, at the front.
        blockers.remember(8 * 3 + 5, same_run);
        assert_eq!(blockers.len, RECENT_BLOCKERS);
        assert_eq!(blockers.recent[0], 8 * 3 + 5);
        assert_eq!(blockers.recent.iter().filter(|&&k| k / 8 == 3).count(), 1);
        // One that blocks again moves to the front.
        let second = blockers.recent[1];
        blockers.blocked_by(1);
        assert_eq!(blockers.recent[0], second);
    }

    #[test]
    fn blockers_past_the_first_are_tried_while_about_one_try_in_five_pays() {
        let mut blockers = RecentBlockers::default();
        blockers.remember(0, same_run);
        assert_eq!(blockers.how_many_to_try(), 1);
        blockers.remember(8, same_run);
        assert_eq!(blockers.how_many_to_try(), 2);
        // Five misses in a row without a hit: only the first is tried from then on.
        for _ in 0..4 {
            blockers.missed(2);
            assert_eq!(blockers.how_many_to_try(), 2);
        }
        blockers.missed(2);
        assert_eq!(blockers.how_many_to_try(), 1);
        // A miss of the first alone says nothing of the others.
        blockers.missed(1);
        assert_eq!(blockers.later_misses, 5);
        // A hit past the first allows four more misses.
        blockers.blocked_by(1);
        assert_eq!(blockers.how_many_to_try(), 2);
    }
}
