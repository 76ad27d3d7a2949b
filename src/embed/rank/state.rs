//! What a host on MPI sets on its interactions between evaluations — the time, which
//! interactions are on, the contact pressure at its own points, quarantine, unpaired
//! interactions — as the serial embedding's setters
//! ([`crate::embed::Embedding::set_time`] and the rest), and the points each rank
//! quarantined.
//!
//! The setters are collective: every rank calls them in the same order with the same
//! arguments. Each rank evaluates only its own points, so a rank told another time, or
//! another switch, would make its share of the terms with it and the summed terms would
//! be no serial embedding's. The arguments are compared over the ranks first (their
//! bits, `MPI_Allreduce` of the least and the largest), and arguments that differ are an
//! error on every rank.

use mpi::collective::SystemOperation;
use mpi::traits::CommunicatorCollectives;

use super::{RankEmbedding, agree};
use crate::embed::{EmbedError, Quarantined, argument};

impl RankEmbedding {
    /// The host's time for the next [`Self::contributions`] (collective, the same on
    /// every rank): conductance models and plugins that depend on t see it, as
    /// [`crate::embed::Embedding::set_time`].
    pub fn set_time(&mut self, time: f64) -> Result<(), EmbedError> {
        self.alike("set_time", &[time.to_bits()])?;
        agree(&self.comm, self.inner.set_time(time))
    }

    /// The time set by [`Self::set_time`] (0 until then).
    pub fn time(&self) -> f64 {
        self.inner.time()
    }

    /// Switch interaction `i` on or off (collective), as [`crate::embed::Embedding::set_active`]:
    /// while off, a flux interaction adds no terms on any rank and its heat is 0.
    pub fn set_active(&mut self, i: usize, on: bool) -> Result<(), EmbedError> {
        self.alike("set_active", &[i as u64, u64::from(on)])?;
        agree(&self.comm, self.inner.set_active(i, on))
    }

    /// Whether interaction `i` is switched on (local).
    pub fn is_active(&self, i: usize) -> bool {
        self.inner.is_active(i)
    }

    /// The contact pressure (Pa, ≥ 0) a conductance model sees at each of this rank's own
    /// contact points of interaction `i`, in the order [`Self::point_fields`] lists them
    /// (collective; every rank gives its own points' values, or every rank `None` to go
    /// back to the enforcement's `Contact Pressure`), as
    /// [`crate::embed::Embedding::set_point_pressures`]. A search drops them.
    pub fn set_point_pressures(
        &mut self,
        i: usize,
        pressures: Option<&[f64]>,
    ) -> Result<(), EmbedError> {
        self.alike(
            "set_point_pressures",
            &[i as u64, u64::from(pressures.is_some())],
        )?;
        let set = match pressures {
            None => self.inner.set_point_pressures(i, None),
            Some(mine) => match self.whole_pressures(i, mine) {
                Ok(Some(whole)) => self.inner.set_point_pressures(i, Some(whole)),
                // No such interaction, or not searched: the serial setter says which.
                Ok(None) => self.inner.set_point_pressures(i, Some(mine.to_vec())),
                Err(e) => Err(e),
            },
        };
        agree(&self.comm, set)
    }

    /// Interaction `i`'s pressure at each of its points from this rank's own points'
    /// `mine` (the other points, which this rank does not evaluate, at 0); `None` when
    /// there is no interaction `i` or it has not been searched.
    fn whole_pressures(&self, i: usize, mine: &[f64]) -> Result<Option<Vec<f64>>, EmbedError> {
        let searched = (self.inner.pairs.get(i)).and_then(|p| {
            p.result
                .as_ref()
                .map(|r| (r.points.len(), p.kept.as_deref()))
        });
        let Some((points, kept)) = searched else {
            return Ok(None);
        };
        let kept: Vec<usize> = kept.map_or_else(|| (0..points).collect(), <[usize]>::to_vec);
        if mine.len() != kept.len() {
            return Err(argument(
                format!(
                    "{} pressures for interaction {i} on rank {}, which owns {} of its contact points",
                    mine.len(),
                    self.rank,
                    kept.len()
                ),
                "give one pressure per point this rank owns, in the order of point_fields on this rank",
            ));
        }
        let mut whole = vec![0.0; points];
        for (&k, &p) in kept.iter().zip(mine) {
            whole[k] = p;
        }
        Ok(Some(whole))
    }

    /// Quarantine the failing points of interaction `i`, or stop doing so (collective),
    /// as [`crate::embed::Embedding::set_quarantine`].
    pub fn set_quarantine(&mut self, i: usize, on: bool) -> Result<(), EmbedError> {
        self.alike("set_quarantine", &[i as u64, u64::from(on)])?;
        agree(&self.comm, self.inner.set_quarantine(i, on))
    }

    /// The points of interaction `i` this rank quarantined so far, in the order they
    /// failed (local): those of its own side-A points whose model failed. The ranks'
    /// lists together are the serial embedding's, each point on the rank that owns it.
    pub fn quarantined(&self, i: usize) -> Vec<Quarantined> {
        self.inner.quarantined(i)
    }

    /// The count of points of interaction `i` quarantined so far over every rank
    /// (collective).
    pub fn quarantined_count(&self, i: usize) -> usize {
        let mine = self.inner.quarantined(i).len() as u64;
        let mut total = 0u64;
        self.comm
            .all_reduce_into(&mine, &mut total, SystemOperation::sum());
        total as usize
    }

    /// Let interaction `i` (every interaction with `None`) pair nothing without an
    /// error, or refuse that again (collective), as [`crate::embed::Embedding::allow_unpaired`].
    pub fn allow_unpaired(&mut self, i: Option<usize>, allow: bool) -> Result<(), EmbedError> {
        let which = i.map_or(u64::MAX, |i| i as u64);
        self.alike("allow_unpaired", &[which, u64::from(allow)])?;
        agree(&self.comm, self.inner.allow_unpaired(i, allow))
    }

    /// `args` (a setter's arguments as bits) are the same on every rank; else an error
    /// on every rank naming the call.
    fn alike(&self, call: &str, args: &[u64]) -> Result<(), EmbedError> {
        let (mut least, mut most) = (vec![0u64; args.len()], vec![0u64; args.len()]);
        self.comm
            .all_reduce_into(args, &mut least[..], SystemOperation::min());
        self.comm
            .all_reduce_into(args, &mut most[..], SystemOperation::max());
        if least == most {
            return Ok(());
        }
        Err(argument(
            format!("{call} was called with different arguments on different ranks"),
            &format!(
                "{call} is collective: call it on every rank, in the same order, with the same arguments (each rank makes its own points' terms with them)"
            ),
        ))
    }
}
