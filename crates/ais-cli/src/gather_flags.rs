//! The gather's command-line flags: the parameters of the scene's `<integrator
//! type="gather">` (see `ais_render::integrators::gather::settings`), spelled with `-` for
//! `_`. Flags override the scene's properties.

use ais_render::integrators::gather::settings::PARAMETERS;
use ais_render::integrators::gather::GatherSettings;
use ais_render::request::{gather_settings, ParameterOverride};
use ais_render::world::World;

/// The gather's parameters as flags (None: not given).
#[derive(clap::Args, Clone, Default)]
pub struct GatherFlags {
    /// Gather proposal: uniform, bsdf, light or mis.
    #[arg(long)]
    strategy: Option<String>,
    /// Candidates per gather, n.
    #[arg(long)]
    rays: Option<String>,
    /// What --rays counts: candidates (AIS traces only the accepted ones) or traced (AIS draws
    /// extra candidates to trace about n).
    #[arg(long)]
    budget: Option<String>,
    /// Candidate placement: halton (scrambled per batch) or random.
    #[arg(long)]
    placement: Option<String>,
    /// A preset of --map, --update and --map-use: off, aggressive, conservative (the talk's
    /// per-batch maps), shared (fixed maps blended from neighbouring gathers), warm (that map
    /// as a warm start, then per-batch learning) or guided (that map folded into the
    /// proposal). The other flags apply after it.
    #[arg(long)]
    ais: Option<String>,
    /// Where a batch's map starts: none (AIS off), batch (empty, learned from its own rays)
    /// or neighbours (blended from neighbouring gathers, see --sharing).
    #[arg(long)]
    map: Option<String>,
    /// How a batch learns from its own rays: off, aggressive or conservative.
    #[arg(long)]
    update: Option<String>,
    /// How the map is used: roulette (skip probably blocked candidates) or proposal (fold the
    /// map into the proposal; reject nothing).
    #[arg(long)]
    map_use: Option<String>,
    /// Roulette's acceptance: affinity (the talk's), sqrt (√affinity), value (always trace
    /// candidates worth over twice the batch's mean) or efficient (√affinity · value / mean).
    #[arg(long)]
    acceptance: Option<String>,
    /// Where neighbours' maps come from: tile (the gathers before them in their tile) or pass
    /// (a learning pass of AIS-off gathers around each tile, one per 4×4 pixels; pass:S for
    /// S×S blocks, S in 1..=16).
    #[arg(long)]
    sharing: Option<String>,
    /// Affinity-map tol (a_min = 1/(tol·h²)); "inf" for no floor.
    #[arg(long)]
    tol: Option<String>,
    /// Affinity-map height in texels (width is twice this).
    #[arg(long)]
    map_res: Option<String>,
    /// map-use proposal: the guide's share of the proposal mixture, in [0, 0.99].
    #[arg(long)]
    guide_fraction: Option<String>,
    /// map field (--ais auto): the cost ratio of a candidate's work besides tracing over
    /// tracing's, or "measured" (the default; give a number to reproduce an image exactly).
    #[arg(long)]
    cost_ratio: Option<String>,
    /// map field: texels per side of a cell's octahedral map (1 to 64).
    #[arg(long)]
    field_res: Option<String>,
    /// map field: a cell's edge in pixel footprints.
    #[arg(long)]
    field_cell: Option<String>,
    /// map field: pseudo-observations per cell (free) and texel (at its cell's visibility).
    #[arg(long)]
    field_prior: Option<String>,
    /// map field: "false" keeps the field for the whole render; "true" (the default) races
    /// it against AIS off in the second and third passes and gathers the rest as AIS off
    /// where it loses.
    #[arg(long)]
    field_race: Option<String>,
    /// map field: "false" keeps --rays candidates in every gather; "true" (the default)
    /// lets the race give fewer (down to n/8, at least 4) to 16 × 16-pixel blocks whose
    /// gathers vary little or whose noise is what the camera sees (most in short renders),
    /// for more samples in the same time.
    #[arg(long)]
    field_sizes: Option<String>,
    /// MIS: the BSDF's share of the candidates, in [0.05, 0.95] (the rest drawn by light
    /// sampling), or "auto" (the default: 0.5, or what `--ais auto` learns).
    #[arg(long)]
    mis_share: Option<String>,
    /// Mitsuba's hide_emitters: "true" hides the emitters the camera sees directly.
    #[arg(long)]
    hide_emitters: Option<String>,
}

impl GatherFlags {
    /// The flag of parameter `name`, if given.
    fn get(&self, name: &str) -> Option<&str> {
        let value = match name {
            "strategy" => &self.strategy,
            "rays" => &self.rays,
            "budget" => &self.budget,
            "placement" => &self.placement,
            "ais" => &self.ais,
            "map" => &self.map,
            "update" => &self.update,
            "map_use" => &self.map_use,
            "acceptance" => &self.acceptance,
            "sharing" => &self.sharing,
            "tol" => &self.tol,
            "map_res" => &self.map_res,
            "guide_fraction" => &self.guide_fraction,
            "cost_ratio" => &self.cost_ratio,
            "field_res" => &self.field_res,
            "field_cell" => &self.field_cell,
            "field_prior" => &self.field_prior,
            "field_race" => &self.field_race,
            "field_sizes" => &self.field_sizes,
            "mis_share" => &self.mis_share,
            "hide_emitters" => &self.hide_emitters,
            _ => &None,
        };
        value.as_deref()
    }

    /// Gather settings: defaults, then the scene's `<integrator>` (gather, or Mitsuba's direct
    /// and path), then these flags; warnings about the scene's integrator are printed (and
    /// refused with `strict`).
    pub fn settings(&self, world: &World, strict: bool) -> Result<GatherSettings, String> {
        let overrides: Vec<ParameterOverride> = PARAMETERS
            .iter()
            .filter_map(|&name| {
                self.get(name).map(|value| ParameterOverride {
                    name,
                    value: value.to_string(),
                })
            })
            .collect();
        let mut warnings = Vec::new();
        let settings = gather_settings(
            world,
            &overrides,
            |name| format!("--{}", name.replace('_', "-")),
            &mut warnings,
        )?;
        crate::report_warnings(&warnings, strict)?;
        Ok(settings)
    }
}
