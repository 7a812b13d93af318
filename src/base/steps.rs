//! Work in resumable steps: a long pass written once as an `async fn` over runs of items
//! ([`runs`]), which pauses when its [`Budget`] of items is spent and resumes where it
//! stopped at the next step. The page's engine keeps a running call's first (quickly
//! compiled) code to its end, so the page runs the job's preparation as a series of short
//! calls, each a step of a budget of items (docs/boundary.md); natively and in the one-call
//! builds the same code runs to its end at once ([`now`], with [`UNLIMITED`]). Nothing here
//! is asynchronous in the sense of waiting: a paused pass is simply polled again.

use std::future::Future;
use std::ops::Range;
use std::pin::Pin;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::task::{Context, Poll, Waker};

pub use crate::base::parallel::RUN;

/// The items a step may still work through; [`UNLIMITED`] never pauses.
pub struct Budget {
    left: AtomicUsize,
    limited: bool,
    /// The pass being worked through ([`Budget::enter`]), for the page's profile.
    pass: Mutex<&'static str>,
}

/// The budget of work run to its end at once.
pub static UNLIMITED: Budget = Budget {
    left: AtomicUsize::new(usize::MAX),
    limited: false,
    pass: Mutex::new(""),
};

impl Budget {
    /// A budget of `items` per step ([`Budget::refill`] before each step).
    pub fn new(items: usize) -> Budget {
        Budget {
            left: AtomicUsize::new(items),
            limited: true,
            pass: Mutex::new(""),
        }
    }

    /// Names the pass the work goes on with (what [`Budget::pass`] tells): a step's calls are
    /// named by the passes they worked through.
    pub fn enter(&self, pass: &'static str) {
        if self.limited
            && let Ok(mut p) = self.pass.lock()
        {
            *p = pass;
        }
    }

    /// The pass named last by [`Budget::enter`] (empty before the first).
    pub fn pass(&self) -> &'static str {
        self.pass.lock().map_or("", |p| *p)
    }

    /// Gives the next step `items` to work through (at least one run's worth is always done).
    pub fn refill(&self, items: usize) {
        self.left.store(items, Ordering::Relaxed);
    }

    /// Whether the work pauses when the budget is spent (not [`UNLIMITED`]).
    pub fn limited(&self) -> bool {
        self.limited
    }

    /// Ends the step here (when limited): a piece of work that is not divided gets a step
    /// of its own, not the end of one.
    pub fn end_step(&self) -> Pause {
        if self.limited {
            self.left.store(0, Ordering::Relaxed);
        }
        Pause { due: self.limited }
    }

    /// Counts `n` items as done; the pass pauses here (its step ends) once none are left.
    pub fn spend(&self, n: usize) -> Pause {
        if !self.limited {
            return Pause { due: false };
        }
        let left = self.left.load(Ordering::Relaxed).saturating_sub(n.max(1));
        self.left.store(left, Ordering::Relaxed);
        Pause { due: left == 0 }
    }
}

/// Where a pass may pause ([`Budget::spend`]): pending once if the budget is spent.
pub struct Pause {
    due: bool,
}

impl Future for Pause {
    type Output = ();
    fn poll(mut self: Pin<&mut Self>, _: &mut Context<'_>) -> Poll<()> {
        if self.due {
            self.due = false;
            Poll::Pending
        } else {
            Poll::Ready(())
        }
    }
}

/// `f(range)` for consecutive ranges of at most [`RUN`] items covering `0..n`, in order,
/// paying each range's items from `budget` (the pass pauses between two ranges when it is
/// spent). As [`crate::base::parallel::in_runs`], each range is a call through a pointer.
pub async fn runs(n: usize, budget: &Budget, f: &mut dyn FnMut(Range<usize>)) {
    let mut at = 0;
    while at < n {
        let end = n.min(at + RUN);
        call(f, at..end);
        budget.spend(end - at).await;
        at = end;
    }
}

#[inline(never)]
fn call(f: &mut dyn FnMut(Range<usize>), r: Range<usize>) {
    f(r)
}

/// Runs a pass of [`UNLIMITED`] budget to its end (it never pauses).
pub fn now<T>(pass: impl Future<Output = T>) -> T {
    let mut pass = std::pin::pin!(pass);
    match pass.as_mut().poll(&mut Context::from_waker(Waker::noop())) {
        Poll::Ready(t) => t,
        Poll::Pending => unreachable!("a pass of unlimited budget paused"),
    }
}

/// A pass being run in steps: [`Stepped::step`] runs it until its budget is spent.
pub struct Stepped<T> {
    pass: Pin<Box<dyn Future<Output = T>>>,
}

impl<T> Stepped<T> {
    pub fn new(pass: impl Future<Output = T> + 'static) -> Stepped<T> {
        Stepped {
            pass: Box::pin(pass),
        }
    }

    /// Runs the pass until it pauses (`None`) or ends (its result). Its budget is refilled
    /// by the caller before.
    pub fn step(&mut self) -> Option<T> {
        match self
            .pass
            .as_mut()
            .poll(&mut Context::from_waker(Waker::noop()))
        {
            Poll::Ready(t) => Some(t),
            Poll::Pending => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::rc::Rc;

    #[test]
    fn a_pass_pauses_when_its_budget_is_spent_and_ends_alike() {
        let budget = Rc::new(Budget::new(0));
        let b = budget.clone();
        let mut pass = Stepped::new(async move {
            let mut seen = Vec::new();
            runs(3 * RUN + 5, &b, &mut |r| seen.push(r)).await;
            seen
        });
        let mut steps = 0;
        let seen = loop {
            budget.refill(2 * RUN);
            steps += 1;
            if let Some(s) = pass.step() {
                break s;
            }
        };
        assert_eq!(steps, 2);
        assert_eq!(
            seen,
            vec![0..RUN, RUN..2 * RUN, 2 * RUN..3 * RUN, 3 * RUN..3 * RUN + 5]
        );
        let all = now(async {
            let mut n = 0;
            runs(3 * RUN + 5, &UNLIMITED, &mut |r| n += r.len()).await;
            n
        });
        assert_eq!(all, 3 * RUN + 5);
    }
}
