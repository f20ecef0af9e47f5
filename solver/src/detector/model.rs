//! The evaluated, checked detector: what the field solver and the plots work with.

use std::path::PathBuf;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::expr::Parameters;
use crate::geometry::{BOUNDARY_TOL_MM, BoundingBox, Solid};
use crate::impurity::{ImpurityContext, ImpurityModel, ImpuritySpec};
use crate::material::Material;
use crate::{Error, Result};

/// Boundary condition on one side of the world box.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundaryKind {
    /// Dirichlet, 0 V (a grounded wall: hat, base plate, cryostat).
    Grounded,
    /// Neumann, zero normal field (a symmetry plane; e.g. the ends of an infinitely long coax).
    Reflecting,
}

/// The three outer sides of the world box (r = 0 is always the symmetry axis).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WorldSide {
    /// r = r_max.
    RMax,
    /// z = z_min.
    ZMin,
    /// z = z_max.
    ZMax,
}

/// The simulated volume [0, r_max] x [z_min, z_max] (mm) and what fills it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct World {
    /// Outer radius, mm.
    pub r_max_mm: f64,
    /// Lower end, mm.
    pub z_min_mm: f64,
    /// Upper end, mm.
    pub z_max_mm: f64,
    /// What fills the world where nothing else is (usually vacuum).
    pub medium: Material,
    /// Boundary conditions on r_max, z_min, z_max.
    pub boundaries: [BoundaryKind; 3],
    /// Optional names of the sides for plots (e.g. "hat wall").
    pub labels: [Option<String>; 3],
}

impl World {
    /// Boundary condition on `side`.
    pub fn boundary(&self, side: WorldSide) -> BoundaryKind {
        self.boundaries[side as usize]
    }

    /// Name of `side`, if the file gives one.
    pub fn label(&self, side: WorldSide) -> Option<&str> {
        self.labels[side as usize].as_deref()
    }

    /// The world box in mm.
    pub fn bbox(&self) -> BoundingBox {
        BoundingBox::new(0.0, self.r_max_mm, self.z_min_mm, self.z_max_mm)
    }
}

/// The potential a contact is held at.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactPotential {
    /// The bias voltage U_B of the run.
    Bias,
    /// A fixed potential in V.
    Fixed(f64),
}

/// An electrode.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contact {
    /// Identifier (unique), as in the capacitance matrix.
    pub id: u32,
    /// Human-readable name.
    pub name: String,
    /// Its potential.
    pub potential: ContactPotential,
    /// Its volume or surface.
    pub geometry: Solid,
}

impl std::fmt::Display for ContactPotential {
    /// `bias` or the potential with its unit, e.g. `0 V`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ContactPotential::Bias => f.write_str("bias"),
            ContactPotential::Fixed(v) => write!(f, "{v} V"),
        }
    }
}

impl Contact {
    /// Potential (V) of this contact when the bias is `bias_v` (V).
    pub fn potential_v(&self, bias_v: f64) -> f64 {
        match self.potential {
            ContactPotential::Bias => bias_v,
            ContactPotential::Fixed(v) => v,
        }
    }

    /// `id (name)`, for messages.
    pub fn label(&self) -> String {
        format!("{} ({})", self.id, self.name)
    }
}

/// What a passive object is electrically.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PassiveKind {
    /// A conductor at 0 V (holding structure, shields).
    Grounded,
    /// An isolated conductor: equipotential with zero net charge.
    Floating,
    /// An insulator with its material's eps_r (PTFE spacers, ...).
    Dielectric,
}

/// Something in the world that is not a contact or the crystal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Passive {
    /// Name.
    pub name: String,
    /// Electrical role.
    pub kind: PassiveKind,
    /// Material.
    pub material: Material,
    /// Shape.
    pub geometry: Solid,
}

/// The semiconductor crystal and its impurity model.
#[derive(Debug, Clone)]
pub struct Semiconductor {
    /// Name.
    pub name: String,
    /// Material (HPGe, eps_r 16).
    pub material: Material,
    /// Shape.
    pub geometry: Solid,
    /// z range and default knots the impurity models refer to.
    pub impurity_context: ImpurityContext,
    pub(crate) impurity: Arc<dyn ImpurityModel>,
    pub(crate) impurity_spec: ImpuritySpec,
    pub(crate) impurity_file: PathBuf,
}

impl Semiconductor {
    /// The active impurity model.
    pub fn impurity(&self) -> &dyn ImpurityModel {
        self.impurity.as_ref()
    }

    /// The specification the active model was built from.
    pub fn impurity_spec(&self) -> &ImpuritySpec {
        &self.impurity_spec
    }

    /// The file the active model came from (the detector file for the default model).
    pub fn impurity_file(&self) -> &std::path::Path {
        &self.impurity_file
    }
}

/// Which part of the model a point belongs to (contacts take precedence over passives, passives
/// over the semiconductor, everything over the world medium).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// Inside or on contact `Detector::contacts[i]`.
    Contact(usize),
    /// Inside passive `Detector::passives[i]`.
    Passive(usize),
    /// Inside the crystal (outside every contact).
    Semiconductor,
    /// The world medium.
    Medium,
}

/// A checked detector description: geometry, materials, contacts, passives, world, impurities.
#[derive(Debug, Clone)]
pub struct Detector {
    /// Name from the file.
    pub name: String,
    /// Free-text description from the file.
    pub description: Option<String>,
    /// The file it came from.
    pub file: PathBuf,
    /// Parameter values in force (file defaults with overrides applied).
    pub parameters: Parameters,
    /// World box and boundaries.
    pub world: World,
    /// The crystal.
    pub semiconductor: Semiconductor,
    /// Electrodes.
    pub contacts: Vec<Contact>,
    /// Passive objects.
    pub passives: Vec<Passive>,
    /// The file's `[grid]` table (grid and accuracy settings for this detector), if it has one;
    /// [`FieldSettings::for_detector`](crate::field::FieldSettings::for_detector) puts it into force.
    pub grid: Option<crate::grid::GridSettings>,
}

impl Detector {
    /// The active impurity model.
    pub fn impurity(&self) -> &dyn ImpurityModel {
        self.semiconductor.impurity()
    }

    /// Region of the point (r, z) in mm; boundaries belong to contacts and conductors.
    pub fn classify(&self, r_mm: f64, z_mm: f64) -> Region {
        let tol = BOUNDARY_TOL_MM;
        if let Some(i) = self
            .contacts
            .iter()
            .position(|c| c.geometry.contains(r_mm, z_mm, tol))
        {
            return Region::Contact(i);
        }
        if let Some(i) = self
            .passives
            .iter()
            .position(|p| p.kind != PassiveKind::Dielectric && p.geometry.contains(r_mm, z_mm, tol))
        {
            return Region::Passive(i);
        }
        if self.semiconductor.geometry.contains(r_mm, z_mm, 0.0) {
            return Region::Semiconductor;
        }
        if let Some(i) = self
            .passives
            .iter()
            .position(|p| p.kind == PassiveKind::Dielectric && p.geometry.contains(r_mm, z_mm, 0.0))
        {
            return Region::Passive(i);
        }
        Region::Medium
    }

    /// Relative permittivity at (r, z) mm; `None` inside conductors (contacts, grounded or
    /// floating passives), where the potential is fixed or uniform.
    pub fn eps_r_at(&self, r_mm: f64, z_mm: f64) -> Option<f64> {
        match self.classify(r_mm, z_mm) {
            Region::Contact(_) => None,
            Region::Passive(i) => match self.passives[i].kind {
                PassiveKind::Dielectric => Some(self.passives[i].material.eps_r),
                _ => None,
            },
            Region::Semiconductor => Some(self.semiconductor.material.eps_r),
            Region::Medium => Some(self.world.medium.eps_r),
        }
    }

    /// Relative permittivity at (r, z) mm ignoring conductors, and whether the point is in the
    /// semiconductor: the material a grid cell is filled with (conductor cells take what is
    /// around them; their nodes are fixed anyway).
    pub fn dielectric_at(&self, r_mm: f64, z_mm: f64) -> (f64, bool) {
        if self.semiconductor.geometry.contains(r_mm, z_mm, 0.0) {
            return (self.semiconductor.material.eps_r, true);
        }
        let eps = self
            .passives
            .iter()
            .find(|p| p.kind == PassiveKind::Dielectric && p.geometry.contains(r_mm, z_mm, 0.0))
            .map_or(self.world.medium.eps_r, |p| p.material.eps_r);
        (eps, false)
    }

    /// Every edge coordinate of every part plus the world box: the ticks a field grid must
    /// carry (r ticks, z ticks; sorted, unique, mm, clipped to the world).
    pub fn ticks(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut r, mut z) = (
            vec![0.0, self.world.r_max_mm],
            vec![self.world.z_min_mm, self.world.z_max_mm],
        );
        let solids = std::iter::once(&self.semiconductor.geometry)
            .chain(self.contacts.iter().map(|c| &c.geometry))
            .chain(self.passives.iter().map(|p| &p.geometry));
        for s in solids {
            let (sr, sz) = s.ticks();
            r.extend(sr);
            z.extend(sz);
        }
        let w = self.world.bbox();
        r.retain(|v| *v >= w.r_min_mm && *v <= w.r_max_mm);
        z.retain(|v| *v >= w.z_min_mm && *v <= w.z_max_mm);
        (
            crate::geometry::sorted_unique(r),
            crate::geometry::sorted_unique(z),
        )
    }

    /// Indices of the contacts held at the bias.
    pub fn bias_contacts(&self) -> Vec<usize> {
        (0..self.contacts.len())
            .filter(|&i| self.contacts[i].potential == ContactPotential::Bias)
            .collect()
    }

    /// Checks that some contact is held at the bias (else a bias voltage acts on nothing):
    /// [`Error::NoBiasContact`] names the file.
    ///
    /// Also refuses a detector whose every contact is at the bias ([`Error::Invalid`] naming
    /// `contacts[K].potential`): nothing then holds the crystal at another potential, no field
    /// builds up between the contacts, and every solve would fail as an undepleted region
    /// joining them.
    pub fn check_bias_contact(&self) -> Result<()> {
        let bias = self.bias_contacts();
        if bias.is_empty() {
            return Err(Error::NoBiasContact {
                file: self.file.clone(),
            });
        }
        if bias.len() == self.contacts.len() && self.contacts.len() > 1 {
            let labels: Vec<String> = self.contacts.iter().map(|c| c.label()).collect();
            return Err(Error::Invalid {
                file: self.file.clone(),
                key: format!("contacts[{}].potential", self.contacts.len() - 1),
                message: format!(
                    "every contact ({}) has potential = \"bias\", so no field builds up between them; \
                     hold at least one at a fixed potential (e.g. potential = 0.0)",
                    labels.join(", ")
                ),
            });
        }
        Ok(())
    }
}
