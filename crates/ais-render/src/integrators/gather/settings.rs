//! The gather's settings: one parameter table, read from the scene's
//! `<integrator type="gather">` and overridden by command-line flags of the same names.
//!
//! | name | type | default | what it sets |
//! |---|---|---|---|
//! | `strategy` | string | `mis` | the proposal: `uniform`, `bsdf`, `light` (or `emitter`), `mis` |
//! | `rays` | integer | 16 | candidates per gather, n (1 to 1,048,576) |
//! | `budget` | string | `candidates` | what `rays` counts: `candidates` (AIS traces only the accepted ones) or `traced` (AIS draws extra candidates to trace about n) |
//! | `placement` | string | `halton` | candidate placement: `halton` (scrambled per batch) or `random` |
//! | `ais` | string | `auto` | a preset of the three map settings below: `off`, `aggressive`, `conservative`, `shared`, `warm`, `guided`, `auto` |
//! | `map` | string | `field` | where a batch's affinity map starts: `none` (AIS off), `batch` (empty, learned from the batch's own rays: the talk's), `neighbours` (blended from neighbouring gathers, see `sharing`), `field` (the visibility field learned in earlier passes over the whole image) |
//! | `update` | string | `off` | how the batch learns from its own rays, in frozen-map epochs: `off`, `aggressive`, `conservative` (the talk's shadow-edge resets) |
//! | `map_use` | string | `both` | how the map is used: `roulette` (skip probably blocked candidates, weight 1/a), `proposal` (fold the map into the proposal, reject nothing; with `map = field`, light sampling draws the environment through the field), or `both` (`map = field` only) |
//! | `acceptance` | string | `affinity` | roulette's acceptance: `affinity` (the talk's), `sqrt`, `value`, `efficient` |
//! | `sharing` | string | `tile` | where `neighbours` maps come from: `tile` (the gathers before it in its tile) or `pass` / `pass:S` (a learning pass over S×S pixel blocks, S in 1..=16; default 4) |
//! | `tol` | float | 1 | the map's floor, a_min = 1/(tol·h²); `inf` for none |
//! | `map_res` | integer | 4 | the map's height h in texels (width 2h), 1 to 1024 |
//! | `guide_fraction` | float | 0.5; 0.75 with `map = field` | `map_use = proposal` or `both`: the guide's share of the proposal (of light sampling's environment draws, with the field), in [0, 0.99] |
//! | `field_res` | integer | 16 | `map = field`: texels per side of a cell's equal-area octahedral map (1 to 64) |
//! | `field_cell` | float | 16 | `map = field`: a cell's edge in pixel footprints at the gather point (rounded to a power of two in world units) |
//! | `field_prior` | float | 2 | `map = field`: pseudo-observations added to every cell (free) and texel (at its cell's visibility): how much evidence it takes to call a direction darker than its cell |
//! | `field_race` | boolean | true | `map = field`: race the field against AIS off in the second and third passes and gather the rest as AIS off where it loses, or where it finds almost nothing to guide or roll; false keeps the field for the whole render (to study it) |
//! | `field_sizes` | boolean | true | `map = field`: after the race passes (raced or not: also under area lights alone), gathers in 16 × 16-pixel blocks whose gathers vary little (in shadow, or lit evenly) get fewer candidates, down to n/8 (at least 4), so that the same time buys more samples for the pixels whose gathers vary most; false keeps `rays` everywhere |
//! | `mis_share` | float or `auto` | `auto` | `strategy = mis`: the BSDF's share of the candidates, in [0.05, 0.95], the rest drawn by light sampling; `auto`: 0.5, except with `map = field`, which learns it from its first passes below 64 candidates and takes 0.25 from 64 on where it guides light sampling |
//! | `hide_emitters` | boolean | false | Mitsuba's: emitters seen directly by the camera add no emission, and the environment seen directly is black |
//! | `cost_ratio` | float or `measured` | `measured` | `map = field` with roulette (64 or more candidates): ρ, what a candidate costs besides tracing over what tracing it adds; measured on 1 gather in 16 of each pass but the last unless given (give it to make such an image reproducible bit for bit; with fewer candidates nothing is timed) |
//!
//! The presets: `off` = `map none`; `aggressive` and `conservative` = `map batch` with that
//! `update`; `shared` = `map neighbours`; `warm` = `map neighbours, update aggressive`;
//! `guided` = `map neighbours, map_use proposal`; `auto` = `map field, map_use both`. A preset sets `map`, `update` and
//! `map_use`; the other parameters keep their values, and any given alongside it apply after
//! it.

use super::acceptance::Acceptance;
use super::strategy::Strategy;
use crate::render::TILE_SIZE;
use crate::scene::{Plugin, Property};
use ais::{BatchConfig, MapConfig, Mode, Stopping};

/// The parameter names, in the order they apply (a preset before the settings it bundles).
pub const PARAMETERS: [&str; 21] = [
    "strategy",
    "rays",
    "budget",
    "placement",
    "ais",
    "map",
    "update",
    "map_use",
    "acceptance",
    "sharing",
    "tol",
    "map_res",
    "guide_fraction",
    "cost_ratio",
    "field_res",
    "field_cell",
    "field_prior",
    "field_race",
    "field_sizes",
    "mis_share",
    "hide_emitters",
];

/// Most rays (candidates) per gather.
pub const MOST_RAYS: u32 = 1 << 20;
/// Largest map height, in texels.
pub const LARGEST_MAP_RES: u32 = 1024;

/// Texels per side of a field cell's map by default: 256 texels of 0.05 sr each (a window a
/// few metres away fills a few of them). Finer maps learn more slowly; pooling their texels
/// with their blocks ([`ais::field::pooling`]) is what makes this size pay for the guides
/// (measured on the repository's scene suite: BENCHMARKS.md, section 5.6).
pub const DEFAULT_FIELD_RES: u32 = 16;

/// A field cell's edge by default, in pixel footprints at the gather point: 16, so that a
/// cell gathers the rays of about 16 × 16 pixels (with 256 texels per cell, smaller cells
/// split their rays too thinly; measured with 4, 8 and 16 on the repository's scene suite,
/// BENCHMARKS.md, section 5.6).
pub const DEFAULT_FIELD_CELL: f32 = 16.0;

/// Where a batch's affinity map starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapSource {
    /// No map: every in-support candidate is traced (AIS off).
    None,
    /// Empty, learned from the batch's own rays (the talk's per-batch maps).
    Batch,
    /// Blended from the rays of neighbouring gathers (see [`Sharing`]) and held fixed, so the
    /// batch is exactly unbiased.
    Neighbours,
    /// No map of its own: the acceptance comes from the visibility field learned over the
    /// whole image in earlier passes ([`ais::field`]), fixed during a pass. Where the field
    /// predicts no gain, the gather traces every candidate and does no map work.
    Field,
}

/// How a batch learns from its own rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Update {
    /// It does not: the map stays as it started.
    Off,
    /// The talk's aggressive update, in frozen-map epochs.
    Aggressive,
    /// The talk's conservative update (shadow-edge resets), in frozen-map epochs.
    Conservative,
}

/// How the map steers the batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapUse {
    /// Russian roulette: a candidate is traced with its acceptance probability and weighs
    /// its inverse.
    Roulette,
    /// Folded into the proposal (see [`super::guiding`], and [`super::field_guide`] for
    /// the field): nothing is rejected.
    Proposal,
    /// The field's two uses at once: light sampling guided by it, and roulette.
    Both,
}

impl MapUse {
    /// Whether candidates are rolled.
    pub fn rolls(self) -> bool {
        matches!(self, MapUse::Roulette | MapUse::Both)
    }

    /// Whether the map shapes the proposal.
    pub fn guides(self) -> bool {
        matches!(self, MapUse::Proposal | MapUse::Both)
    }
}

/// A named bundle of [`MapSource`], [`Update`] and [`MapUse`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// No map.
    Off,
    /// The talk's per-batch aggressive map.
    Aggressive,
    /// The talk's per-batch conservative map.
    Conservative,
    /// Fixed maps blended from neighbouring gathers, used for roulette.
    Shared,
    /// That map as a warm start, then aggressive learning from the batch's rays.
    Warm,
    /// That map folded into the proposal.
    Guided,
    /// The learned visibility field, standing aside where it predicts no gain.
    Auto,
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 7] = [
        Preset::Off,
        Preset::Aggressive,
        Preset::Conservative,
        Preset::Shared,
        Preset::Warm,
        Preset::Guided,
        Preset::Auto,
    ];

    /// Its name.
    pub fn name(self) -> &'static str {
        self.word()
    }

    /// The preset of this name.
    pub fn parse(name: &str) -> Option<Preset> {
        Self::parse_word(name).ok()
    }

    fn axes(self) -> (MapSource, Update, MapUse) {
        use MapSource as S;
        match self {
            Preset::Off => (S::None, Update::Off, MapUse::Roulette),
            Preset::Aggressive => (S::Batch, Update::Aggressive, MapUse::Roulette),
            Preset::Conservative => (S::Batch, Update::Conservative, MapUse::Roulette),
            Preset::Shared => (S::Neighbours, Update::Off, MapUse::Roulette),
            Preset::Warm => (S::Neighbours, Update::Aggressive, MapUse::Roulette),
            Preset::Guided => (S::Neighbours, Update::Off, MapUse::Proposal),
            Preset::Auto => (S::Field, Update::Off, MapUse::Both),
        }
    }
}

/// Where [`MapSource::Neighbours`] maps come from. Both keep the image independent of
/// threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sharing {
    /// The gathers before it in its tile, in the tile's fixed pixel order (see
    /// [`ais::shared`]): free, but one-sided, and a tile's first gathers have none.
    TileOrder,
    /// A learning pass: AIS-off gathers at the centres of `stride × stride` pixel blocks
    /// over the tile and one block around it, run before the tile (see
    /// [`super::learning_pass`]): neighbours on every side, for extra gathers.
    LearningPass {
        /// Block edge in pixels (1 to [`TILE_SIZE`]).
        stride: u32,
    },
}

/// The learning pass's default block edge, in pixels.
pub const LEARNING_STRIDE: u32 = 4;

impl Sharing {
    /// Parses "tile", "pass" (blocks of [`LEARNING_STRIDE`]) or "pass:S" (blocks of S
    /// pixels).
    pub fn parse(name: &str) -> Option<Sharing> {
        match name.split_once(':') {
            None if name == "tile" => Some(Sharing::TileOrder),
            None if name == "pass" => Some(Sharing::LearningPass {
                stride: LEARNING_STRIDE,
            }),
            Some(("pass", stride)) => stride
                .parse()
                .ok()
                .filter(|s| (1..=TILE_SIZE as u32).contains(s))
                .map(|stride| Sharing::LearningPass { stride }),
            _ => None,
        }
    }
}

/// What a gather's `rays` counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayBudget {
    /// About `rays` traced rays per gather: every epoch draws ⌈n_e / acceptance rate⌉
    /// candidates ([`ais::Stopping::CandidateBudget`]). The talk's reading: AIS buys more
    /// candidates with the same rays.
    Traced,
    /// Exactly `rays` candidates per gather, of which AIS traces only the accepted
    /// ([`ais::Stopping::FixedCandidates`]): AIS makes each gather cheaper.
    Candidates,
}

/// A Mitsuba `direct` or `path` integrator read as gather settings.
pub struct MitsubaIntegrator {
    /// The settings: the defaults with its `hide_emitters`.
    pub settings: GatherSettings,
    /// Its properties the gather does not use, with their lines.
    pub ignored: Vec<(String, u32)>,
}

/// Settings of the multi-ray gather integrator (see the module's parameter table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherSettings {
    /// The proposal sampler.
    pub strategy: Strategy,
    /// Rays (candidates) per gather, n.
    pub rays: u32,
    /// What `rays` counts.
    pub budget: RayBudget,
    /// Halton (the talk's) or independent random candidates.
    pub placement: ais::Placement,
    /// Where the batch's map starts.
    pub map: MapSource,
    /// How the batch learns from its own rays.
    pub update: Update,
    /// How the map steers the batch.
    pub map_use: MapUse,
    /// How a candidate's acceptance probability follows from the map.
    pub acceptance: Acceptance,
    /// Where neighbours' maps come from.
    pub sharing: Sharing,
    /// The map's tol (a_min = 1 / (tol h²)).
    pub tol: f32,
    /// The map's height in texels.
    pub map_height: u32,
    /// `map_use = proposal` or `both`: the guide's share α of the proposal mixture
    /// `(1 − α) p + α g`; `None`: the default for the map ([`GatherSettings::guide_share`]).
    pub guide_fraction: Option<f32>,
    /// `map = field`: the cost ratio ρ (a candidate's work besides tracing, over what
    /// tracing it adds) its acceptance uses; `None`: measured in the render.
    pub cost_ratio: Option<f32>,
    /// `map = field`: texels per side of a cell's octahedral map.
    pub field_res: u32,
    /// `map = field`: a cell's edge, in pixel footprints at the gather point.
    pub field_cell: f32,
    /// `map = field`: pseudo-observations added to every cell (free) and texel (at its
    /// cell's visibility).
    pub field_prior: f32,
    /// `map = field`: whether the field races AIS off and may stand aside (see
    /// [`super::race`]); false keeps it for the whole render.
    pub field_race: bool,
    /// `map = field`: whether the race also chooses the candidates per gather per block
    /// of the image (see [`super::gather_sizes`]); false keeps `rays` everywhere.
    pub field_sizes: bool,
    /// `strategy = mis`: the BSDF's share of the candidates; `None`: 0.5, or what the field
    /// chooses (`map = field`).
    pub mis_share: Option<f32>,
    /// Mitsuba's `hide_emitters`: camera rays add no emission of the emitters they hit
    /// directly, and the environment seen directly is black.
    pub hide_emitters: bool,
}

impl Default for GatherSettings {
    fn default() -> Self {
        let map = MapConfig::default();
        GatherSettings {
            strategy: Strategy::Mis,
            rays: 16,
            // Measured: with AIS off, exactly n candidates in one Halton set beat the traced
            // budget's 4 separately scrambled epochs by 1.27-1.57× at equal time on every
            // scene, and shared maps gain only with this budget.
            budget: RayBudget::Candidates,
            placement: ais::Placement::Halton,
            // `auto`. Measured on eleven scenes (BENCHMARKS.md §5.6): the field's guided light
            // sampling gains 1.4–2.6× at equal time in rooms and courtyards lit by a sky and
            // stands aside elsewhere (within noise, at most a few percent of overhead).
            map: MapSource::Field,
            update: Update::Off,
            map_use: MapUse::Both,
            acceptance: Acceptance::Affinity,
            sharing: Sharing::TileOrder,
            tol: map.tol,
            map_height: map.height,
            guide_fraction: None,
            cost_ratio: None,
            field_res: DEFAULT_FIELD_RES,
            field_cell: DEFAULT_FIELD_CELL,
            field_prior: ais::field::PRIOR_FREE,
            field_race: true,
            field_sizes: true,
            mis_share: None,
            hide_emitters: false,
        }
    }
}

/// A setting written as one of a few words.
trait Choice: Copy + PartialEq + 'static {
    /// What the setting is called in errors.
    const WHAT: &'static str;
    /// Its words and values.
    const WORDS: &'static [(&'static str, Self)];

    /// The word for this value.
    fn word(self) -> &'static str {
        Self::WORDS
            .iter()
            .find(|(_, v)| *v == self)
            .map_or("", |(name, _)| name)
    }

    /// The value of `word`, or an error listing the words.
    fn parse_word(word: &str) -> Result<Self, String> {
        Self::WORDS
            .iter()
            .find(|(name, _)| *name == word)
            .map(|&(_, v)| v)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::WORDS.iter().map(|(name, _)| *name).collect();
                format!("unknown {} \"{word}\" ({})", Self::WHAT, names.join(", "))
            })
    }
}

impl Choice for RayBudget {
    const WHAT: &'static str = "budget";
    const WORDS: &'static [(&'static str, Self)] = &[
        ("candidates", RayBudget::Candidates),
        ("traced", RayBudget::Traced),
    ];
}

impl Choice for ais::Placement {
    const WHAT: &'static str = "placement";
    const WORDS: &'static [(&'static str, Self)] = &[
        ("halton", ais::Placement::Halton),
        ("random", ais::Placement::Random),
    ];
}

impl Choice for MapSource {
    const WHAT: &'static str = "map";
    const WORDS: &'static [(&'static str, Self)] = &[
        ("none", MapSource::None),
        ("batch", MapSource::Batch),
        ("neighbours", MapSource::Neighbours),
        ("field", MapSource::Field),
    ];
}

impl Choice for Update {
    const WHAT: &'static str = "update";
    const WORDS: &'static [(&'static str, Self)] = &[
        ("off", Update::Off),
        ("aggressive", Update::Aggressive),
        ("conservative", Update::Conservative),
    ];
}

impl Choice for MapUse {
    const WHAT: &'static str = "map_use";
    const WORDS: &'static [(&'static str, Self)] = &[
        ("roulette", MapUse::Roulette),
        ("proposal", MapUse::Proposal),
        ("both", MapUse::Both),
    ];
}

impl Choice for Preset {
    const WHAT: &'static str = "AIS preset";
    const WORDS: &'static [(&'static str, Self)] = &[
        ("off", Preset::Off),
        ("aggressive", Preset::Aggressive),
        ("conservative", Preset::Conservative),
        ("shared", Preset::Shared),
        ("warm", Preset::Warm),
        ("guided", Preset::Guided),
        ("auto", Preset::Auto),
    ];
}

fn number<T: std::str::FromStr>(value: &str, what: &str) -> Result<T, String> {
    value
        .trim()
        .parse()
        .map_err(|_| format!("{what} \"{value}\" is not a number of the right kind"))
}

/// Parses "true" or "false"; the error names the parameter `what`.
fn boolean(value: &str, what: &str) -> Result<bool, String> {
    match value.trim() {
        "true" => Ok(true),
        "false" => Ok(false),
        _ => Err(format!("{what} \"{value}\" is not true or false")),
    }
}

impl GatherSettings {
    /// The defaults with a preset's map settings.
    pub fn preset(preset: Preset) -> Self {
        GatherSettings::default().with_preset(preset)
    }

    /// These settings with a preset's map settings.
    pub fn with_preset(self, preset: Preset) -> Self {
        let (map, update, map_use) = preset.axes();
        GatherSettings {
            map,
            update,
            map_use,
            ..self
        }
    }

    /// The preset these map settings match, if any.
    pub fn matching_preset(&self) -> Option<Preset> {
        Preset::ALL
            .into_iter()
            .find(|p| p.axes() == (self.map, self.update, self.map_use))
    }

    /// Sets the parameter `name` (one of [`PARAMETERS`]) from its text.
    pub fn set(&mut self, name: &str, value: &str) -> Result<(), String> {
        match name {
            "strategy" => {
                self.strategy = Strategy::parse(value).ok_or_else(|| {
                    format!("unknown strategy \"{value}\" (uniform, bsdf, light, mis)")
                })?
            }
            "rays" => self.rays = number(value, "rays")?,
            "budget" => self.budget = Choice::parse_word(value)?,
            "placement" => self.placement = Choice::parse_word(value)?,
            "ais" => *self = self.with_preset(Choice::parse_word(value)?),
            "mis_share" => {
                self.mis_share = match value {
                    "auto" => None,
                    _ => Some(number(value, "mis_share")?),
                }
            }
            _ => return self.set_map_parameter(name, value),
        }
        Ok(())
    }

    /// [`GatherSettings::set`] for the map's parameters.
    fn set_map_parameter(&mut self, name: &str, value: &str) -> Result<(), String> {
        match name {
            "map" => self.map = Choice::parse_word(value)?,
            "update" => self.update = Choice::parse_word(value)?,
            "map_use" => self.map_use = Choice::parse_word(value)?,
            "acceptance" => {
                self.acceptance = Acceptance::parse(value).ok_or_else(|| {
                    format!("unknown acceptance \"{value}\" (affinity, sqrt, value, efficient)")
                })?
            }
            "sharing" => {
                self.sharing = Sharing::parse(value).ok_or_else(|| {
                    format!("unknown sharing \"{value}\" (tile, pass, or pass:S with S in 1..=16)")
                })?
            }
            "tol" => self.tol = number(value, "tol")?,
            "map_res" => self.map_height = number(value, "map_res")?,
            "guide_fraction" => self.guide_fraction = Some(number(value, "guide_fraction")?),
            "hide_emitters" => self.hide_emitters = boolean(value, "hide_emitters")?,
            "field_race" => self.field_race = boolean(value, "field_race")?,
            "field_sizes" => self.field_sizes = boolean(value, "field_sizes")?,
            "field_res" => self.field_res = number(value, "field_res")?,
            "field_cell" => self.field_cell = number(value, "field_cell")?,
            "field_prior" => self.field_prior = number(value, "field_prior")?,
            "cost_ratio" => {
                self.cost_ratio = match value {
                    "measured" => None,
                    _ => Some(number(value, "cost_ratio")?),
                }
            }
            _ => {
                return Err(format!(
                    "unknown gather parameter \"{name}\" (known: {})",
                    PARAMETERS.join(", ")
                ))
            }
        }
        Ok(())
    }

    /// The defaults overridden by the properties of a scene's `<integrator type="gather">`;
    /// an error names the line.
    pub fn from_properties(plugin: &Plugin) -> Result<Self, (u32, String)> {
        let mut settings = GatherSettings::default();
        if let Some((name, line)) = plugin.unknown_properties(&PARAMETERS).into_iter().next() {
            return Err((
                line,
                format!(
                    "unknown gather parameter \"{name}\" (known: {})",
                    PARAMETERS.join(", ")
                ),
            ));
        }
        for name in PARAMETERS {
            let Some(property) = plugin.properties.get(name) else {
                continue;
            };
            let text = match &property.value {
                Property::String(s) => s.clone(),
                Property::Integer(i) => i.to_string(),
                Property::Float(f) => f.to_string(),
                Property::Boolean(b) => b.to_string(),
                other => {
                    return Err((
                        property.line,
                        format!("\"{name}\" cannot be a {}", other.kind()),
                    ))
                }
            };
            settings
                .set(name, &text)
                .map_err(|message| (property.line, message))?;
        }
        settings
            .validate()
            .map_err(|message| (plugin.line, message))?;
        Ok(settings)
    }

    /// The settings for a scene whose integrator is Mitsuba's `direct` or `path`: the
    /// defaults, with its `hide_emitters`; its other properties are listed to be warned of
    /// (the gather chooses its own samples).
    pub fn from_mitsuba_integrator(plugin: &Plugin) -> Result<MitsubaIntegrator, (u32, String)> {
        let mut settings = GatherSettings::default();
        if let Some(property) = plugin.properties.get("hide_emitters") {
            match property.value {
                Property::Boolean(hide) => settings.hide_emitters = hide,
                ref other => {
                    return Err((
                        property.line,
                        format!("\"hide_emitters\" cannot be a {}", other.kind()),
                    ))
                }
            }
        }
        Ok(MitsubaIntegrator {
            settings,
            ignored: plugin.unknown_properties(&["hide_emitters"]),
        })
    }

    /// Checks ranges and combinations.
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MOST_RAYS).contains(&self.rays) {
            return Err(format!("rays must lie in 1..={MOST_RAYS}"));
        }
        if self.tol.is_nan() || self.tol <= 0.0 {
            return Err("tol must be positive (or inf)".into());
        }
        if !(1..=LARGEST_MAP_RES).contains(&self.map_height) {
            return Err(format!("map_res must lie in 1..={LARGEST_MAP_RES}"));
        }
        if !(0.0..=0.99).contains(&self.guide_share()) {
            return Err("guide_fraction must lie in [0, 0.99]".into());
        }
        if !(1..=64).contains(&self.field_res) {
            return Err("field_res must lie in 1..=64".into());
        }
        if !(self.field_cell > 0.0 && self.field_cell <= 1e6) {
            return Err("field_cell must lie in (0, 1e6]".into());
        }
        if !(0.0..=1e6).contains(&self.field_prior) {
            return Err("field_prior must lie in [0, 1e6]".into());
        }
        if let Some(share) = self.mis_share {
            if !(0.05..=0.95).contains(&share) {
                return Err("mis_share must lie in [0.05, 0.95] (or be \"auto\")".into());
            }
        }
        if let Some(ratio) = self.cost_ratio {
            if !(0.0..=1e6).contains(&ratio) {
                return Err("cost_ratio must lie in [0, 1e6] (or be \"measured\")".into());
            }
        }
        self.validate_map()
    }

    fn validate_map(&self) -> Result<(), String> {
        match (self.map, self.update, self.map_use) {
            (MapSource::None, Update::Off, MapUse::Roulette) => Ok(()),
            (MapSource::None, _, _) => {
                Err("map none (AIS off) takes neither an update nor map_use proposal".into())
            }
            (MapSource::Field, Update::Off, _) if self.acceptance == Acceptance::Affinity => Ok(()),
            (MapSource::Field, _, _) => {
                Err("map field (auto) chooses its own acceptance and takes no update rule".into())
            }
            (_, _, MapUse::Both) => {
                Err("map_use both needs the visibility field (map field)".into())
            }
            (MapSource::Batch, Update::Off, _) => {
                Err("a per-batch map (map batch) needs an update rule to learn with".into())
            }
            (MapSource::Batch, _, MapUse::Proposal) => {
                Err("map_use proposal needs a fixed map (map neighbours, update off)".into())
            }
            (
                MapSource::Neighbours,
                Update::Aggressive | Update::Conservative,
                MapUse::Proposal,
            ) => Err("map_use proposal needs a fixed map (update off)".into()),
            (_, _, MapUse::Proposal) if self.acceptance != Acceptance::Affinity => {
                Err("map_use proposal rejects no candidate, so it takes no acceptance rule".into())
            }
            _ => Ok(()),
        }
    }

    /// Why parameter `name` changes nothing under these settings, if it does not: each
    /// parameter belongs to one kind of map (see the module's table), and a parameter given
    /// for another is worth a warning rather than silence.
    pub fn inapplicable(&self, name: &str) -> Option<String> {
        let field = self.map == MapSource::Field;
        let why = match name {
            "cost_ratio" | "field_res" | "field_cell" | "field_prior" | "field_race"
            | "field_sizes"
                if !field =>
            {
                Some("it applies only to the visibility field (map field: ais auto)")
            }
            "cost_ratio" if !super::field::field_rolls(self) => {
                return Some(format!(
                    "the field rolls only with map_use roulette or both and at least {} rays, \
                     and only then is a cost ratio used",
                    super::field::LEAST_ROLLING_RAYS
                ))
            }
            "sharing" if self.map != MapSource::Neighbours => Some(
                "it applies only to maps blended from neighbours (map neighbours: ais shared, \
                 warm or guided)",
            ),
            "tol" | "map_res" if matches!(self.map, MapSource::None | MapSource::Field) => Some(
                "it applies only to the per-batch and neighbours' maps (ais aggressive, \
                 conservative, shared, warm or guided)",
            ),
            "guide_fraction" if !self.map_use.guides() => {
                Some("it applies only where a map guides the proposal (map_use proposal or both)")
            }
            "acceptance" if self.map == MapSource::None => {
                Some("AIS off (map none) rejects no candidate")
            }
            "mis_share" if self.strategy != Strategy::Mis => {
                Some("it splits the candidates of MIS only (strategy mis)")
            }
            _ => None,
        };
        why.map(str::to_string)
    }

    /// The guide's share of the proposal: as given, else [`super::guiding::GUIDE_FRACTION`]
    /// for a neighbours' map and [`super::field_guide::FIELD_GUIDE_FRACTION`] for the field.
    pub fn guide_share(&self) -> f32 {
        self.guide_fraction.unwrap_or(match self.map {
            MapSource::Field => super::field_guide::FIELD_GUIDE_FRACTION,
            _ => super::guiding::GUIDE_FRACTION,
        })
    }

    /// Whether each gather starts from maps learned at neighbouring gather points.
    pub fn shares_maps(&self) -> bool {
        self.map == MapSource::Neighbours
    }

    /// Whether AIS is on (the batch has a map).
    pub fn has_map(&self) -> bool {
        self.map != MapSource::None
    }

    /// A short description of the map settings: the preset's name, or the axes.
    pub fn ais_label(&self) -> String {
        let axes = self.matching_preset().map_or_else(
            || {
                format!(
                    "map {}, update {}, map_use {}",
                    self.map.word(),
                    self.update.word(),
                    self.map_use.word()
                )
            },
            |p| p.name().to_string(),
        );
        match self.acceptance {
            Acceptance::Affinity => axes,
            other => format!("{axes}, acceptance {}", other.name()),
        }
    }

    /// The batch configuration of the library.
    pub fn batch_config(&self) -> BatchConfig {
        let base = BatchConfig {
            stopping: match self.budget {
                RayBudget::Traced => Stopping::CandidateBudget,
                RayBudget::Candidates => Stopping::FixedCandidates,
            },
            placement: self.placement,
            ..BatchConfig::default()
        };
        if matches!(self.map, MapSource::None | MapSource::Field) {
            // The field's acceptance comes from the host (the gather), not from a batch map.
            return BatchConfig {
                affinity: None,
                learning: ais::Learning::Off,
                ..base
            };
        }
        let map = MapConfig {
            height: self.map_height,
            tol: self.tol,
            ..MapConfig::default()
        };
        let (mode, learning) = match self.update {
            // A fixed map: exactly unbiased.
            Update::Off => (map.mode, ais::Learning::Off),
            Update::Aggressive => (Mode::Aggressive, base.learning),
            Update::Conservative => (Mode::Conservative, base.learning),
        };
        BatchConfig {
            affinity: Some(MapConfig { mode, ..map }),
            learning,
            ..base
        }
    }
}
