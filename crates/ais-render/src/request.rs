//! What a front end asks to render, turned into a world and gather settings: the part of
//! scene loading that the `ais` command and the Python package share.

use crate::default_scene::default_world;
use crate::error::InputError;
use crate::integrators::gather::settings::PARAMETERS;
use crate::integrators::gather::GatherSettings;
use crate::scene::{load_scene, parse_scene, Plugin};
use crate::world::World;
use std::path::Path;

/// Where a scene comes from.
#[derive(Clone, Copy, Debug)]
pub enum SceneSource<'a> {
    /// A Mitsuba 3 XML file.
    File(&'a Path),
    /// Mitsuba 3 XML text; `name` stands for the file in messages and its folder is where
    /// relative file names point.
    Text {
        /// The XML.
        text: &'a str,
        /// What messages call it.
        name: &'a Path,
    },
    /// The built-in default scene.
    BuiltIn,
}

/// A scene to load, with the overrides a user gave.
#[derive(Clone, Copy, Debug)]
pub struct SceneRequest<'a> {
    /// The scene.
    pub source: SceneSource<'a>,
    /// `$name` parameters of the scene file.
    pub defines: &'a [(String, String)],
    /// The film size, if it overrides the scene's.
    pub resolution: Option<(u32, u32)>,
    /// The built-in scene's size when `resolution` is not given.
    pub default_resolution: (u32, u32),
}

/// What messages call the built-in default scene.
pub const BUILT_IN_NAME: &str = "<built-in default scene>";

/// The world a request names (its resolution overridden if asked), with the scene's
/// warnings in [`World::warnings`]; memory is checked before geometry is built. An error
/// names the file and, where known, the line.
pub fn load_world(request: &SceneRequest) -> Result<World, InputError> {
    let description = match request.source {
        SceneSource::File(path) => load_scene(path, request.defines),
        SceneSource::Text { text, name } => parse_scene(name, text, request.defines),
        SceneSource::BuiltIn => {
            let (width, height) = request.resolution.unwrap_or(request.default_resolution);
            crate::limits::check_image_memory((width, height))
                .map_err(|message| InputError::new(BUILT_IN_NAME, message))?;
            let mut world = default_world(width, height);
            world
                .warnings
                .extend(request.defines.iter().map(|(name, value)| {
                    format!("{name}={value} is not used: the built-in scene has no parameters")
                }));
            return Ok(world);
        }
    };
    let mut description = description?;
    if let Some(resolution) = request.resolution {
        description.resolution = resolution;
    }
    crate::limits::check_image_memory(description.resolution)
        .map_err(|message| InputError::new(&description.file, message))?;
    World::from_description(description)
}

/// A gather parameter given by the user, named as in the parameter table (`rays`,
/// `ais`, …).
#[derive(Clone, Debug)]
pub struct ParameterOverride<'a> {
    /// The parameter's name.
    pub name: &'a str,
    /// Its value, as text.
    pub value: String,
}

/// The gather's settings for `world`: the defaults, then its scene's `<integrator>` (gather,
/// or Mitsuba's direct and path), then `overrides`. Scene properties the gather does not
/// use are added to `warnings`; an override's error names it through `spell` (e.g. as a
/// flag, `--map-res`).
pub fn gather_settings(
    world: &World,
    overrides: &[ParameterOverride],
    spell: impl Fn(&str) -> String,
    warnings: &mut Vec<String>,
) -> Result<GatherSettings, String> {
    let file = world.description.file.display();
    let at = |(line, message): (u32, String)| format!("{file}:{line}: {message}");
    let integrator = world
        .description
        .integrator
        .as_ref()
        .map(|plugin| rendering_integrator(plugin, &file, warnings));
    let mut settings = match integrator {
        Some(plugin) if plugin.kind == "gather" => {
            GatherSettings::from_properties(plugin).map_err(at)?
        }
        Some(plugin) => mitsuba_integrator_settings(plugin, &file, warnings).map_err(at)?,
        None => GatherSettings::default(),
    };
    if let Some(unknown) = overrides.iter().find(|o| !PARAMETERS.contains(&o.name)) {
        return Err(format!(
            "unknown gather parameter \"{}\" (known: {})",
            unknown.name,
            PARAMETERS.join(", ")
        ));
    }
    for name in PARAMETERS {
        for given in overrides.iter().filter(|o| o.name == name) {
            settings
                .set(name, &given.value)
                .map_err(|message| format!("{}: {message}", spell(name)))?;
        }
    }
    settings.validate()?;
    // Each parameter given, by the scene (with its line) or by an override.
    let scene_given = integrator
        .filter(|plugin| plugin.kind == "gather")
        .into_iter()
        .flat_map(|plugin| plugin.properties.iter())
        .map(|(name, property)| {
            let said = format!("{file}:{}: \"{name}\"", property.line);
            (name.as_str(), said)
        });
    let flag_given = overrides.iter().map(|o| (o.name, spell(o.name)));
    warnings.extend(scene_given.chain(flag_given).filter_map(|(name, said)| {
        let why = settings.inapplicable(name)?;
        Some(format!("{said} is ignored: {why}"))
    }));
    Ok(settings)
}

/// The settings for a scene whose integrator is Mitsuba's (`direct`, `path`), with a
/// warning that it renders as the gather and one for each property the gather ignores.
fn mitsuba_integrator_settings(
    plugin: &Plugin,
    file: &impl std::fmt::Display,
    warnings: &mut Vec<String>,
) -> Result<GatherSettings, (u32, String)> {
    warnings.push(format!(
        "{file}:{}: integrator \"{}\" rendered with ais's gather (MIS): direct light \
         only, indirect light is not computed",
        plugin.line, plugin.kind
    ));
    let read = GatherSettings::from_mitsuba_integrator(plugin)?;
    warnings.extend(read.ignored.into_iter().map(|(name, line)| {
        format!(
            "{file}:{line}: \"{name}\" of integrator \"{}\" is ignored (the gather takes rays and strategy)",
            plugin.kind
        )
    }));
    Ok(read.settings)
}

/// The integrator that renders: Mitsuba's `moment` and `aov` wrap another, which renders
/// in their place (with a warning: their extra outputs are not written).
fn rendering_integrator<'a>(
    plugin: &'a Plugin,
    file: &impl std::fmt::Display,
    warnings: &mut Vec<String>,
) -> &'a Plugin {
    let mut current = plugin;
    while matches!(current.kind.as_str(), "moment" | "aov") {
        let Some(inner) = current.children.iter().find(|c| c.tag == "integrator") else {
            break;
        };
        warnings.push(format!(
            "{file}:{}: integrator \"{}\" is unwrapped: its inner \"{}\" renders, and its \
             extra channels are not written",
            current.line, current.kind, inner.kind
        ));
        current = inner;
    }
    current
}

/// Settings from a configuration text of `name=value` words (the gather's parameter names),
/// applied in the parameter table's order on top of `base`: e.g. "ais=shared
/// acceptance=efficient".
pub fn settings_from_words(base: &GatherSettings, text: &str) -> Result<GatherSettings, String> {
    let mut given = Vec::new();
    for word in text.split_whitespace() {
        let (name, value) = word
            .split_once('=')
            .ok_or_else(|| format!("\"{word}\" in \"{text}\" is not name=value"))?;
        if !PARAMETERS.contains(&name) {
            return Err(format!(
                "unknown gather parameter \"{name}\" in \"{text}\" (known: {})",
                PARAMETERS.join(", ")
            ));
        }
        given.push((name, value));
    }
    let mut settings = *base;
    for name in PARAMETERS {
        for (_, value) in given.iter().filter(|(n, _)| *n == name) {
            settings
                .set(name, value)
                .map_err(|m| format!("\"{text}\": {m}"))?;
        }
    }
    settings
        .validate()
        .map_err(|m| format!("\"{text}\": {m}"))?;
    Ok(settings)
}
