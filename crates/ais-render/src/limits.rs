//! Limits on resources, checked before work starts, so that an absurd request fails at once with a clear
//! error instead of hanging, or aborting when memory runs out.

/// Bytes the BVH and the shading data hold per triangle (primitive, node share, normals and
/// indices), a generous estimate.
const BYTES_PER_TRIANGLE: u64 = 160;

/// Bytes a render holds per pixel: the film's sums and counts, the image, the traced-ray AOV
/// and the tiles' results before they are merged.
const BYTES_PER_PIXEL: u64 = 3 * 8 + 4 + 3 * 4 + 4 + 3 * 4 + 4;

/// The most threads per core: beyond it the threads mostly wait for each other.
pub const THREADS_PER_CORE: usize = 4;

/// The machine's cores.
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Checks a requested thread count; `forced` allows more than 4 per core.
pub fn check_threads(threads: usize, forced: bool) -> Result<(), String> {
    let most = THREADS_PER_CORE * cores();
    if threads == 0 {
        return Err("--threads must be at least 1".into());
    }
    if threads > most && !forced {
        return Err(format!(
            "--threads {threads} is more than {THREADS_PER_CORE} per core ({most} on this \
             machine's {} cores); more threads only wait for each other (--force-threads \
             allows it)",
            cores()
        ));
    }
    Ok(())
}

/// Memory the system can still give, in bytes (Linux's MemAvailable), if known.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Checks that the geometry of `triangles` triangles fits in the memory available.
pub fn check_geometry_memory(triangles: usize) -> Result<(), String> {
    let needed = triangles as u64 * BYTES_PER_TRIANGLE;
    match available_memory() {
        Some(available) if needed > available / 10 * 8 => Err(format!(
            "{triangles} triangles need about {:.1} GiB for the BVH, and {:.1} GiB of memory is \
             available",
            needed as f64 / (1u64 << 30) as f64,
            available as f64 / (1u64 << 30) as f64
        )),
        _ => Ok(()),
    }
}

/// Checks that an image of `width × height` pixels fits in the memory available.
pub fn check_image_memory((width, height): (u32, u32)) -> Result<(), String> {
    let needed = width as u64 * height as u64 * BYTES_PER_PIXEL;
    let Some(available) = available_memory() else {
        return Ok(());
    };
    if needed > available / 10 * 8 {
        return Err(format!(
            "a {width}×{height} image needs about {:.1} GiB for its film, and {:.1} GiB of \
             memory is available; render a smaller image (--resolution) or in parts",
            needed as f64 / (1u64 << 30) as f64,
            available as f64 / (1u64 << 30) as f64
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_requests_are_refused() {
        assert!(check_threads(0, false).is_err());
        assert!(check_threads(1, false).is_ok());
        assert!(check_threads(10_000, false)
            .unwrap_err()
            .contains("per core"));
        assert!(check_threads(64, true).is_ok());
        if available_memory().is_some() {
            assert!(check_image_memory((64, 64)).is_ok());
            assert!(check_image_memory((65536, 65536))
                .unwrap_err()
                .contains("GiB"));
        }
    }
}
