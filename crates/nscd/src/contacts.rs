//! The contacts of a step and the memory that carries their impulses to the next.
//!
//! [`ContactSet`] holds the contacts detected at the predicted configuration (sorted by
//! candidate, then antagonist, see [`crate::detect`]) and, from the end of the previous
//! step, the impulse and the stick status of every contact keyed by (candidate,
//! antagonist). A contact found again starts the contact problem from the impulse it
//! ended the previous step with (warm start) and takes the static friction coefficient
//! if it was sticking; a new one starts from zero.

use porofrac_particles::Disks;

use crate::body::RigidBody;
use crate::detect::{Antagonist, Contact, Detector};

/// The key of a contact from one step to the next: (candidate, antagonist).
pub type ContactKey = (u32, Antagonist);

/// What a contact of the previous step left for the warm start.
#[derive(Clone, Copy, Debug)]
struct Previous {
    key: ContactKey,
    p: [f64; 2],
    stick: bool,
}

/// The contacts of the current step and the impulses of the previous one.
#[derive(Clone, Debug, Default)]
pub struct ContactSet {
    /// The contacts of the step, sorted by key after detection.
    pub(crate) list: Vec<Contact>,
    /// The previous step's contacts, sorted by key.
    previous: Vec<Previous>,
}

impl ContactSet {
    /// The contacts of the step (after the contact problem: with their impulses).
    pub fn as_slice(&self) -> &[Contact] {
        &self.list
    }

    /// Detect the contacts of the step at disk centres `x` and body offsets `offsets`
    /// (the predicted configuration), replacing the current ones; the memory of the
    /// previous step is kept.
    pub fn detect(
        &mut self,
        detector: &mut Detector,
        x: &[[f64; 2]],
        disks: &Disks,
        bodies: &[RigidBody],
        offsets: &[[f64; 2]],
        alert: f64,
    ) -> Result<(), crate::NscdError> {
        detector.detect(x, &disks.r, bodies, offsets, alert, &mut self.list)
    }

    /// The impulse and stick status the contact `key` ended the previous step with, or
    /// zero and not sticking for a new contact. Keys must be asked in increasing order,
    /// with `cursor` starting at 0: the lookup is a merge of two sorted lists.
    pub fn warm_start(&self, cursor: &mut usize, key: ContactKey) -> ([f64; 2], bool) {
        while *cursor < self.previous.len() && self.previous[*cursor].key < key {
            *cursor += 1;
        }
        match self.previous.get(*cursor) {
            Some(q) if q.key == key => (q.p, q.stick),
            _ => ([0.0; 2], false),
        }
    }

    /// The memory of the previous step, sorted by key: key, impulse and stick status of
    /// each contact (for a checkpoint).
    pub fn memory(&self) -> Vec<(ContactKey, [f64; 2], bool)> {
        self.previous
            .iter()
            .map(|q| (q.key, q.p, q.stick))
            .collect()
    }

    /// Replace the memory of the previous step by `memory` (as [`ContactSet::memory`]
    /// gave it; sorted again by key).
    pub fn set_memory(&mut self, memory: &[(ContactKey, [f64; 2], bool)]) {
        self.previous.clear();
        self.previous.extend(
            memory
                .iter()
                .map(|&(key, p, stick)| Previous { key, p, stick }),
        );
        self.previous.sort_unstable_by_key(|q| q.key);
    }

    /// Keep the impulses and the stick status of the step's contacts for the next step's
    /// warm start. A contact sticks when its normal impulse (with the cohesive shift) is
    /// positive and its tangential impulse strictly inside the friction cone
    /// (`|P_t| < μ P_n (1 − 1e-9)`).
    pub fn remember(&mut self) {
        self.previous.clear();
        self.previous.extend(self.list.iter().map(|c| {
            let pn = c.p[0] + c.shift;
            Previous {
                key: (c.i, c.other),
                p: c.p,
                stick: pn > 0.0 && c.p[1].abs() < c.mu * pn * (1.0 - 1e-9),
            }
        }));
        // Sorted by key for the merge of the next warm start (colouring permutes).
        self.previous.sort_unstable_by_key(|q| q.key);
    }
}
