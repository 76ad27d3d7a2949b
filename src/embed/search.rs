use super::{EmbedError, Embedding, Enforcement, Pair, argument};
use std::sync::OnceLock;

use crate::enforce::interface::Form;
use crate::search::pairing::{SearchResult, SearchStats, Searcher, SurfaceGeometry};

impl Embedding {
    /// Number of interactions.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// The surface names (side A, side B) of interaction `i`.
    pub fn surfaces(&self, i: usize) -> Option<(&str, &str)> {
        self.pairs
            .get(i)
            .map(|p| (p.side_a.name.as_str(), p.side_b.name.as_str()))
    }

    /// Pair every interaction's side-A points with side-B faces anew (a full search).
    pub fn search(&mut self) -> Result<(), EmbedError> {
        let all: Vec<usize> = (0..self.pairs.len()).collect();
        self.search_some(&all)
    }

    /// Pair the side-A points of the interactions `which` anew (a full search of each),
    /// keeping the others' pairings; after a [`Self::move_nodes`], the interactions
    /// whose search schedule is due.
    pub fn search_some(&mut self, which: &[usize]) -> Result<(), EmbedError> {
        if let Some(&i) = which.iter().find(|&&i| i >= self.pairs.len()) {
            return Err(argument(
                format!("no interaction {i} ({} interactions)", self.pairs.len()),
                "number the interactions from 0 in the order they were added",
            ));
        }
        for &i in which {
            let p = &mut self.pairs[i];
            if p.b.faces.is_empty() {
                return Err(argument(
                    format!("side B `{}` has no faces", p.side_b.name),
                    "check the surface's faces",
                ));
            }
            let searcher = Searcher::new(&p.b, &p.settings);
            let mut result =
                searcher.search(&p.a, &p.b, &p.settings, self.integration, p.subdomain);
            if let Some(treatment) = p.overclosure {
                result.treat_overclosure(treatment);
            }
            let tie = match &p.enforcement {
                Enforcement::Tie { .. } => true,
                Enforcement::Flux { form, .. } => matches!(
                    form,
                    Form::TiedNitsche | Form::TiedInteriorPenalty | Form::Penalty
                ),
            };
            if tie && result.stats.matched == 0 {
                return Err(argument(
                    format!(
                        "interaction {} / {} ties two surfaces that do not overlap anywhere ({} points, none paired)",
                        p.side_a.name, p.side_b.name, result.stats.points
                    ),
                    "check the surfaces' faces and the search tolerances (normal tolerance, field factor)",
                ));
            }
            if !tie && !p.allow_unpaired && result.stats.matched == 0 {
                return Err(EmbedError::NothingPaired {
                    side_a: p.side_a.name.clone(),
                    side_b: p.side_b.name.clone(),
                    why: crate::scene::why_nothing_paired(&result.stats),
                });
            }
            p.searcher = Some(searcher);
            p.result = Some(result);
            p.pressures = None;
            p.points = OnceLock::new();
            p.kept = None;
        }
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
        Ok(())
    }

    /// Let interaction `i` (or every interaction, with `None`) pair nothing without
    /// [`EmbedError::NothingPaired`]; see [`super::Interaction::allow_unpaired`].
    pub fn allow_unpaired(&mut self, i: Option<usize>, allow: bool) -> Result<(), EmbedError> {
        match i {
            None => self.pairs.iter_mut().for_each(|p| p.allow_unpaired = allow),
            Some(i) => {
                let count = self.pairs.len();
                let p = self.pairs.get_mut(i).ok_or_else(|| {
                    argument(
                        format!("no interaction {i}, there are {count}"),
                        "interaction indices are 0-based, in the order they were added",
                    )
                })?;
                p.allow_unpaired = allow;
            }
        }
        Ok(())
    }

    /// The host's time for the next [`Self::contributions`]: conductance models and
    /// plugins that depend on t (a Lua expression of `t`, a plugin's time argument)
    /// see it. Must be finite.
    pub fn set_time(&mut self, time: f64) -> Result<(), EmbedError> {
        if !time.is_finite() {
            return Err(argument(
                format!("the time {time} is not finite"),
                "pass the host's current time in seconds",
            ));
        }
        self.time = time;
        Ok(())
    }

    /// The time set by [`Self::set_time`] (0 until then).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The nodes moved: keep every pairing, place its points again on the moved faces
    /// and measure gaps anew (`Update Search Every n Steps` between full searches).
    /// Call [`Self::search`] to pair anew.
    pub fn move_nodes(&mut self, coords: &[[f64; 3]]) -> Result<(), EmbedError> {
        if coords.len() != self.mesh.coords.len() {
            return Err(argument(
                format!(
                    "{} coordinates for {} nodes",
                    coords.len(),
                    self.mesh.coords.len()
                ),
                "pass every node's new coordinates, in node order",
            ));
        }
        if let Some(k) = coords.iter().position(|x| x.iter().any(|c| !c.is_finite())) {
            return Err(argument(
                format!("node {k} moved to a non-finite position {:?}", coords[k]),
                "check the host's displacement field",
            ));
        }
        self.mesh.coords = coords.to_vec();
        for p in &mut self.pairs {
            Self::place(&self.mesh, p)?;
            if let Some(r) = &mut p.result {
                r.update_geometry(&p.a, &p.b);
            }
            p.points = OnceLock::new();
            p.kept = None;
            p.kept = None;
            if let Some(e) = &mut self.evaluation {
                e.outdate();
            }
            if let Some(s) = &mut p.searcher {
                s.refit(&p.b);
            }
        }
        Ok(())
    }

    /// The geometry of `p`'s two surfaces on the mesh's present coordinates.
    fn place(mesh: &crate::mesh::Mesh, p: &mut Pair) -> Result<(), EmbedError> {
        for (surface, geometry) in [(&p.side_a, &mut p.a), (&p.side_b, &mut p.b)] {
            *geometry = SurfaceGeometry::from_surface(mesh, surface, &mesh.coords)
                .map_err(|e| argument(e.to_string(), "interfaces are searched in 3-D"))?;
        }
        // A periodic pair's side A is the image of the moved surface.
        if let Some(image) = &mut p.image {
            p.a = p.a.mapped(image.map.as_mut(), &image.name).map_err(|e| {
                argument(
                    format!(
                        "periodic interaction {} / {}: {e}",
                        p.side_a.name, p.side_b.name
                    ),
                    "the map failed on the moved nodes of side A",
                )
            })?;
        }
        Ok(())
    }

    /// Interaction `i` takes the surfaces `side_a` and `side_b` (the same names, other
    /// faces: element death made them again); its pairing is cleared until the next
    /// search ([`Self::search_some`]).
    pub(crate) fn replace_surfaces(
        &mut self,
        i: usize,
        side_a: crate::surface::ContactSurface,
        side_b: crate::surface::ContactSurface,
    ) -> Result<(), EmbedError> {
        let Some(p) = self.pairs.get_mut(i) else {
            return Err(argument(
                format!("no interaction {i}"),
                "number the interactions from 0",
            ));
        };
        p.side_a = side_a;
        p.side_b = side_b;
        Self::place(&self.mesh, p)?;
        p.result = None;
        p.searcher = None;
        p.points = OnceLock::new();
        p.kept = None;
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
        Ok(())
    }

    /// The search statistics of interaction `i` (after a search).
    pub fn search_stats(&self, i: usize) -> Option<&SearchStats> {
        self.pairs
            .get(i)
            .and_then(|p| p.result.as_ref())
            .map(|r| &r.stats)
    }

    /// Interaction `i`'s side-A geometry (for a periodic pair, the image), side-B
    /// geometry and pairing, as the last search or move left them.
    pub fn pairing_of(
        &self,
        i: usize,
    ) -> Option<(&SurfaceGeometry, &SurfaceGeometry, &SearchResult)> {
        let p = self.pairs.get(i)?;
        Some((&p.a, &p.b, p.result.as_ref()?))
    }

    pub(super) fn searched(p: &Pair) -> Result<&SearchResult, EmbedError> {
        p.result.as_ref().ok_or_else(|| EmbedError::Order {
            what: format!(
                "interaction {} / {} has not been searched",
                p.side_a.name, p.side_b.name
            ),
            help: "call search() after adding interactions".into(),
        })
    }
}
