//! Files in Mitsuba's serialized mesh format, written for the reader's tests.

/// A file in Mitsuba's serialized format (`version` 3 or 4) holding shapes whose
/// decompressed streams are `bodies` (see [`serialized_body`]).
pub fn serialized(bodies: &[Vec<u8>], version: u16) -> Vec<u8> {
    use std::io::Write;
    let mut data = Vec::new();
    let mut offsets = Vec::new();
    for body in bodies {
        offsets.push(data.len() as u64);
        data.extend(0x041Cu16.to_le_bytes());
        data.extend(version.to_le_bytes());
        let mut encoder =
            flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        encoder.write_all(body).unwrap();
        data.extend(encoder.finish().unwrap());
    }
    for offset in &offsets {
        if version == 4 {
            data.extend(offset.to_le_bytes());
        } else {
            data.extend((*offset as u32).to_le_bytes());
        }
    }
    data.extend((offsets.len() as u32).to_le_bytes());
    data
}

/// The decompressed stream of a serialized shape: `positions` and `triangles`, texture
/// coordinates when given, in single or `double` precision, named when `version` is 4.
pub fn serialized_body(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    texcoords: Option<&[[f64; 2]]>,
    double: bool,
    version: u16,
) -> Vec<u8> {
    let flags: u32 = if double { 0x2000 } else { 0x1000 } | if texcoords.is_some() { 2 } else { 0 };
    let mut body = flags.to_le_bytes().to_vec();
    if version == 4 {
        body.extend(b"shape\0");
    }
    body.extend((positions.len() as u64).to_le_bytes());
    body.extend((triangles.len() as u64).to_le_bytes());
    let mut real = |value: f64| {
        if double {
            body.extend(value.to_le_bytes())
        } else {
            body.extend((value as f32).to_le_bytes())
        }
    };
    positions.iter().flatten().for_each(|&v| real(v));
    texcoords
        .into_iter()
        .flatten()
        .flatten()
        .for_each(|&v| real(v));
    body.extend(triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
    body
}
