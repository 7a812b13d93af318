//! The preparation of a [`Job`] in resumable steps (the page's short calls, docs/page.md):
//! [`Job::prepare_in_steps`] and [`Job::prepare_drafted`] give a [`Preparation`] whose
//! [`Preparation::step`] works through a budget of items a call ([`Job::build_in_steps`]).

use crate::base::error::Error;
use crate::base::steps::{Budget, Stepped};
use crate::model::models::Model;
use crate::model::spec as job;
use crate::pipeline::Job;
use crate::pipeline::handoff::{DraftHook, DraftTo};
use std::cell::Cell;
use std::rc::Rc;
use std::sync::Arc;

impl Job {
    /// [`Job::from_models`] in resumable steps (the page's engine keeps a running call's
    /// first code to its end, so the preparation is a series of short calls): nothing is done
    /// until [`Preparation::step`], which works through a budget of items (facets, corners,
    /// vertices) a call, every pass in turn, and hands out the job after the last. The job (or
    /// the refusal) is the one [`Job::from_models`] makes, whatever the budgets.
    pub fn prepare_in_steps(models: Arc<Vec<Model>>, spec: &job::JobSpec) -> Preparation {
        Job::prepare_drafted(models, spec, None)
    }

    /// [`Job::prepare_in_steps`] that also hands `draft` the job's [`Draft`] as soon as its
    /// parts are merged (when the plane heights are known), before the passes that need the
    /// whole mesh: the page's other workers slice from it while this preparation goes on.
    /// [`Preparation::as_drafted`] then tells whether the job is the draft's.
    pub fn prepare_drafted(
        models: Arc<Vec<Model>>,
        spec: &job::JobSpec,
        draft: Option<DraftHook>,
    ) -> Preparation {
        Job::prepare_drafted_to(models, spec, draft.map(DraftTo::Hook))
    }

    /// [`Job::prepare_drafted`] that hands the draft to a hook or writes it, in steps of
    /// their own, into a sink ([`DraftTo`]).
    pub fn prepare_drafted_to(
        models: Arc<Vec<Model>>,
        spec: &job::JobSpec,
        draft: Option<DraftTo>,
    ) -> Preparation {
        let budget = Rc::new(Budget::new(0));
        let drafted = Rc::new(Cell::new(None));
        let (b, d) = (budget.clone(), drafted.clone());
        let spec = spec.clone();
        Preparation {
            budget,
            drafted,
            passes: ("", ""),
            pass: Some(Stepped::new(async move {
                Job::build_in_steps(&models, &spec, &b, draft, &d).await
            })),
        }
    }
}

/// [`Job::from_models`] in resumable steps: [`Job::prepare_in_steps`], then
/// [`Preparation::step`] until it hands out the job.
pub struct Preparation {
    /// The items the next step may work through.
    budget: Rc<Budget>,
    /// Whether the job is its draft's, once made (`None`: no draft was made).
    drafted: Rc<Cell<Option<bool>>>,
    /// The passes the last step began and ended in ([`Preparation::passes`]).
    passes: (&'static str, &'static str),
    /// `None` once the job was handed out (or a step failed).
    pass: Option<Stepped<Result<Job, Error>>>,
}

impl Preparation {
    /// Works through about `items` items of the preparation (at least one run of them, see
    /// [`crate::base::steps::runs`]; a few passes between the long ones are not divided): `Ok(None)`
    /// while there is more, the job at the end. After the job or an error there is nothing
    /// left: an `Internal` error.
    pub fn step(&mut self, items: usize) -> Result<Option<Job>, Error> {
        let Some(pass) = self.pass.as_mut() else {
            return Err(Error::Internal(
                "the job's preparation has already ended".into(),
            ));
        };
        self.budget.refill(items);
        let first = self.budget.pass();
        let made = pass.step();
        self.passes = (first, self.budget.pass());
        match made {
            None => Ok(None),
            Some(made) => {
                self.pass = None;
                made.map(Some)
            }
        }
    }

    /// The passes the last step worked in: the one it began in and the one it ended in (the
    /// same when it stayed in one), such as "weld" or "facet index" (empty before the first
    /// step began any).
    pub fn passes(&self) -> (&'static str, &'static str) {
        self.passes
    }

    /// Once the job is made: whether it is the one its [`Draft`] slices (the same mesh,
    /// planes and units' facet runs: no facet dropped, no crack closed, no shell turned), so
    /// that the draft's workers need only its [`Job::confirmation`]; `None` when no draft was
    /// made (or the job is not made yet).
    pub fn as_drafted(&self) -> Option<bool> {
        self.drafted.get()
    }
}
