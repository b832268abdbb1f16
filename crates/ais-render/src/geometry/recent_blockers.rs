//! What blocked a gather's earlier shadow rays, tried before a traversal.

/// The primitives that blocked a gather's rays (rays that share an origin), for
/// [`super::Geometry::occluded_after`] to try before a traversal: the blocked rays of a
/// gather in a room mostly meet the same few surfaces (walls, a ceiling). It only saves
/// time: whatever it holds, the answers are a traversal's.
///
/// A gather whose rays were mostly blocked passes its blockers on to the next gather of
/// its tile, a neighbour, which then likely meets the same surfaces from its first ray
/// ([`RecentBlockers::passed_on`]); one whose rays were mostly free passes on nothing, as
/// its blockers would cost a test for each of the next gather's free rays. Tiles are the
/// same whatever the thread count, and so is the work.
#[derive(Clone, Copy, Debug, Default)]
pub struct RecentBlockers {
    /// Blocking primitives, the most recently useful first, no two that make the same test.
    recent: [Blocker; RECENT_BLOCKERS],
    /// How many of `recent` are filled.
    len: usize,
    /// Tests of the blockers past the first, and how many of them found the ray blocked:
    /// those are tried only while they pay.
    later_tests: u32,
    later_hits: u32,
    /// The gather's rays that were blocked, and those that were free.
    blocked: u32,
    free: u32,
    /// The gather's rays tested against the box around everything first that passed it by,
    /// and that did not.
    box_passed: u32,
    box_entered: u32,
}

/// A primitive that blocked a ray.
#[derive(Clone, Copy, Debug, Default)]
struct Blocker {
    /// The primitive, in the accelerator's order.
    index: u32,
    /// What names its test: the same for two primitives tested together.
    test: u32,
}

/// How many blockers a gather remembers.
const RECENT_BLOCKERS: usize = 8;

/// How many tests past the first a gather makes before it asks whether they pay.
const FREE_TESTS: u32 = 8;

impl RecentBlockers {
    /// How many of the blockers the next ray tries: the first always, the rest while about
    /// one of their tests in five finds a ray blocked. A run's test costs a few of a
    /// traversal's steps; below that rate the tests cost more than they save, as in
    /// foliage, where a blocking leaf rarely blocks another ray (the rate is the one at
    /// which, in the renders of BENCHMARKS.md, the rooms keep their gain and the foliage
    /// loses least). The first tests are free of the rule.
    pub(super) fn how_many_to_try(&self) -> usize {
        if self.later_tests <= 5 * self.later_hits + FREE_TESTS {
            self.len
        } else {
            self.len.min(1)
        }
    }

    /// What the next gather of the tile starts from: these blockers and what their tests
    /// paid, if at least half of the rays were blocked (where fewer were, trying them
    /// would cost a free ray more than a blocked one saves), and nothing otherwise.
    pub fn passed_on(&self) -> Self {
        if self.blocked == 0 || self.blocked < self.free {
            return RecentBlockers::default();
        }
        RecentBlockers {
            blocked: 0,
            free: 0,
            box_passed: 0,
            box_entered: 0,
            ..*self
        }
    }

    /// Whether the next ray is tested against the box around everything first, before
    /// the blockers: while the box has been passed by about as many of the gather's rays as
    /// not (under an open sky most rays pass it by, and need no blocker's test; in a room
    /// none do). Once it stops, the box is tried only after the blockers, before a
    /// traversal, for the rest of the gather's rays ([`super::Geometry::occluded_after`]).
    pub(super) fn tries_box_first(&self) -> bool {
        self.box_entered <= self.box_passed + 1
    }

    /// A ray tested against the box first passed it by, or not.
    pub(super) fn box_tried(&mut self, passed: bool) {
        self.box_passed += passed as u32;
        self.box_entered += !passed as u32;
    }

    /// A ray was found free (by a traversal, or without one: a shaft's answer).
    pub(crate) fn note_free(&mut self) {
        self.free += 1;
    }

    /// `recent[at]` blocked the ray: it moves to the front.
    pub(super) fn blocked_by(&mut self, at: usize) {
        self.blocked += 1;
        if at > 0 {
            self.later_tests += at as u32;
            self.later_hits += 1;
            self.put_first(at, self.recent[at]);
        }
    }

    /// None of the first `tried` blocked the ray.
    pub(super) fn missed(&mut self, tried: usize) {
        self.later_tests += tried.saturating_sub(1) as u32;
    }

    /// The `at`-th blocker to try (the primitive, in the accelerator's order).
    pub(super) fn index(&self, at: usize) -> usize {
        self.recent[at].index as usize
    }

    /// A ray was blocked by a primitive that a traversal found: the blocker, with what
    /// names its test (the same for primitives tested together), put at the front in the
    /// place of one that makes the same test; the oldest drops out when all places are
    /// taken.
    pub(super) fn remember(&mut self, index: usize, test: u32) {
        self.blocked += 1;
        let known = self.recent[..self.len].iter().position(|k| k.test == test);
        let at = known.unwrap_or_else(|| {
            self.len = (self.len + 1).min(RECENT_BLOCKERS);
            self.len - 1
        });
        let blocker = Blocker {
            index: index as u32,
            test,
        };
        self.put_first(at, blocker);
    }

    /// `blocker` put first, those before place `at` moved one place down over it (a loop,
    /// not `rotate_right`, which is not worked out inline for a slice this short).
    #[inline]
    fn put_first(&mut self, at: usize, blocker: Blocker) {
        for k in (1..=at).rev() {
            self.recent[k] = self.recent[k - 1];
        }
        self.recent[0] = blocker;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Remembers triangle `index`, tested with its run of eight.
    fn remember(blockers: &mut RecentBlockers, index: usize) {
        blockers.remember(index, (index / 8) as u32);
    }

    #[test]
    fn the_most_recently_useful_blocker_comes_first_and_the_oldest_drops_out() {
        let mut blockers = RecentBlockers::default();
        for index in 0..RECENT_BLOCKERS + 1 {
            remember(&mut blockers, index * 8);
        }
        assert_eq!(blockers.len, RECENT_BLOCKERS);
        assert_eq!(blockers.index(0), RECENT_BLOCKERS * 8);
        assert!(
            (0..RECENT_BLOCKERS).all(|at| blockers.index(at) != 0),
            "the oldest is gone"
        );
        // A primitive of a run already there takes that run's place, at the front.
        remember(&mut blockers, 8 * 3 + 5);
        assert_eq!(blockers.len, RECENT_BLOCKERS);
        assert_eq!(blockers.index(0), 8 * 3 + 5);
        let of_run_3 = (0..RECENT_BLOCKERS).filter(|&at| blockers.index(at) / 8 == 3);
        assert_eq!(of_run_3.count(), 1);
        // One that blocks again moves to the front.
        let second = blockers.index(1);
        blockers.blocked_by(1);
        assert_eq!(blockers.index(0), second);
    }

    #[test]
    fn blockers_past_the_first_are_tried_while_about_one_test_in_five_pays() {
        let mut blockers = RecentBlockers::default();
        remember(&mut blockers, 0);
        assert_eq!(blockers.how_many_to_try(), 1);
        remember(&mut blockers, 8);
        remember(&mut blockers, 16);
        assert_eq!(blockers.how_many_to_try(), 3);
        // The free tests past the first find nothing; the next one stops them.
        for _ in 0..FREE_TESTS / 2 {
            assert_eq!(blockers.how_many_to_try(), 3);
            blockers.missed(3);
        }
        assert_eq!(blockers.later_tests, FREE_TESTS);
        assert_eq!(blockers.how_many_to_try(), 3);
        blockers.missed(2);
        assert_eq!(blockers.how_many_to_try(), 1);
        // A miss of the first alone tests none of the others.
        blockers.missed(1);
        assert_eq!(blockers.later_tests, FREE_TESTS + 1);
        // A hit at the third place (two tests past the first) allows five tests more.
        blockers.blocked_by(2);
        assert_eq!(blockers.later_tests, FREE_TESTS + 3);
        assert_eq!(blockers.how_many_to_try(), 3);
        blockers.missed(3);
        assert_eq!(blockers.how_many_to_try(), 3);
        blockers.missed(3);
        assert_eq!(blockers.how_many_to_try(), 1);
    }

    #[test]
    fn a_gather_passes_its_blockers_on_when_half_its_rays_or_more_were_blocked() {
        let mut blockers = RecentBlockers::default();
        assert_eq!(blockers.passed_on().len, 0, "no ray, nothing to pass on");
        remember(&mut blockers, 0);
        remember(&mut blockers, 8);
        blockers.missed(2);
        blockers.note_free();
        // Two blocked, one free: the blockers and what their tests paid go on, and the
        // next gather counts its own rays afresh.
        let next = blockers.passed_on();
        assert_eq!((next.len, next.index(0), next.index(1)), (2, 8, 0));
        assert_eq!(next.later_tests, blockers.later_tests);
        assert_eq!((next.blocked, next.free), (0, 0));
        // As many free as blocked still passes them on; one more free ray does not.
        blockers.note_free();
        assert_eq!(blockers.passed_on().len, 2);
        blockers.note_free();
        let next = blockers.passed_on();
        assert_eq!((next.len, next.later_tests, next.blocked), (0, 0, 0));
        // A ray blocked by a blocker tried first counts as blocked too.
        blockers.blocked_by(0);
        assert_eq!(blockers.passed_on().len, 2);
    }

    #[test]
    fn the_box_is_tried_first_while_about_as_many_rays_pass_it_as_enter_it() {
        let mut blockers = RecentBlockers::default();
        assert!(blockers.tries_box_first(), "a gather's first ray");
        blockers.box_tried(false);
        assert!(blockers.tries_box_first(), "one entered, none passed");
        blockers.box_tried(false);
        assert!(
            !blockers.tries_box_first(),
            "two entered, none passed (a room)"
        );
        // (The renderer tries no more boxes first then; the rule alone, counted on.)
        blockers.box_tried(true);
        assert!(blockers.tries_box_first(), "two entered, one passed");
        for _ in 0..5 {
            blockers.box_tried(true);
        }
        // Six passed: up to seven entered.
        for _ in 2..8 {
            assert!(blockers.tries_box_first(), "under an open sky");
            blockers.box_tried(false);
        }
        assert!(!blockers.tries_box_first());
        // The next gather counts its own rays afresh.
        remember(&mut blockers, 0);
        assert!(blockers.passed_on().tries_box_first());
    }
}
