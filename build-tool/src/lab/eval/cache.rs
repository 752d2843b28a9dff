//! The result cache: one small JSON file per (figure, method, target, N, seed)
//! under `DIR/cache/`, written atomically, so that an interrupted or repeated run
//! skips finished work; and a point-set cache for our optimized sets (the expensive
//! part), shared by every figure that uses the same target.
//!
//! Values are stored bit-exactly (as the `u64` bit patterns of the `f64`s, next to
//! a readable copy), so a rerun from the cache reproduces the first run's output
//! byte for byte. Every entry carries a *fingerprint* of the settings it was
//! computed with (epochs, metric effort, ...); an entry whose fingerprint differs
//! from the current one is a miss and is recomputed and overwritten.

use anyhow::{Context, Result};
use glam::DVec2;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Named values of one realization (metric or estimate name -> value).
pub type Values = BTreeMap<String, f64>;

/// What one cached result is the result of.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CacheKey {
    /// Figure name, e.g. `fig2`.
    pub figure: String,
    /// Method name, e.g. `owen-sobol`.
    pub method: String,
    /// Target (panel) name, e.g. `quarter-disc`.
    pub target: String,
    /// Number of points.
    pub n: usize,
    /// Realization seed.
    pub seed: u64,
}

/// On-disk form of a result entry.
#[derive(Serialize, Deserialize)]
struct Entry {
    figure: String,
    method: String,
    target: String,
    n: usize,
    seed: u64,
    fingerprint: String,
    /// Readable copy (not read back).
    values: BTreeMap<String, f64>,
    /// Bit patterns of `values` (what is read back).
    bits: BTreeMap<String, u64>,
}

/// On-disk form of a cached point set.
#[derive(Serialize, Deserialize)]
struct PointsEntry {
    fingerprint: String,
    n: usize,
    seed: u64,
    /// Bit patterns of the coordinates.
    bits: Vec<[u64; 2]>,
}

/// Replaces every character outside `[A-Za-z0-9._-]` by `_` (file-name safe).
pub fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A cache rooted at a directory (normally `DIR/cache`).
#[derive(Clone, Debug)]
pub struct Cache {
    root: PathBuf,
}

impl Cache {
    /// A cache under `root` (created lazily on the first write).
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    /// The cache's root directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// File of a result entry:
    /// `ROOT/FIGURE/TARGET/METHOD/nN-sSEED.json`.
    pub fn entry_path(&self, key: &CacheKey) -> PathBuf {
        self.root
            .join(sanitize(&key.figure))
            .join(sanitize(&key.target))
            .join(sanitize(&key.method))
            .join(format!("n{}-s{}.json", key.n, key.seed))
    }

    /// The cached values of `key` if an entry exists, parses, names the same key
    /// and has this `fingerprint`; `None` otherwise (a miss, never an error).
    pub fn get(&self, key: &CacheKey, fingerprint: &str) -> Option<Values> {
        let text = std::fs::read_to_string(self.entry_path(key)).ok()?;
        let e: Entry = serde_json::from_str(&text).ok()?;
        let same = e.figure == key.figure
            && e.method == key.method
            && e.target == key.target
            && e.n == key.n
            && e.seed == key.seed
            && e.fingerprint == fingerprint;
        same.then(|| {
            e.bits
                .into_iter()
                .map(|(k, b)| (k, f64::from_bits(b)))
                .collect()
        })
    }

    /// Stores `values` for `key` atomically.
    pub fn put(&self, key: &CacheKey, fingerprint: &str, values: &Values) -> Result<()> {
        let path = self.entry_path(key);
        write_json(
            &path,
            &Entry {
                figure: key.figure.clone(),
                method: key.method.clone(),
                target: key.target.clone(),
                n: key.n,
                seed: key.seed,
                fingerprint: fingerprint.to_string(),
                values: values.clone(),
                bits: values
                    .iter()
                    .map(|(k, v)| (k.clone(), v.to_bits()))
                    .collect(),
            },
        )
    }

    /// File of a cached point set: `ROOT/points/GROUP/nN-sSEED.json`.
    pub fn points_path(&self, group: &str, n: usize, seed: u64) -> PathBuf {
        self.root
            .join("points")
            .join(sanitize(group))
            .join(format!("n{n}-s{seed}.json"))
    }

    /// A cached point set of `group` (e.g. `ours-square-quarter-disc`), if present
    /// with this `fingerprint` and `n` points.
    pub fn get_points(
        &self,
        group: &str,
        n: usize,
        seed: u64,
        fingerprint: &str,
    ) -> Option<Vec<DVec2>> {
        let text = std::fs::read_to_string(self.points_path(group, n, seed)).ok()?;
        let e: PointsEntry = serde_json::from_str(&text).ok()?;
        (e.fingerprint == fingerprint && e.n == n && e.seed == seed && e.bits.len() == n).then(
            || {
                e.bits
                    .iter()
                    .map(|[x, y]| DVec2::new(f64::from_bits(*x), f64::from_bits(*y)))
                    .collect()
            },
        )
    }

    /// Stores a point set atomically.
    pub fn put_points(
        &self,
        group: &str,
        seed: u64,
        fingerprint: &str,
        points: &[DVec2],
    ) -> Result<()> {
        let path = self.points_path(group, points.len(), seed);
        write_json(
            &path,
            &PointsEntry {
                fingerprint: fingerprint.to_string(),
                n: points.len(),
                seed,
                bits: points
                    .iter()
                    .map(|p| [p.x.to_bits(), p.y.to_bits()])
                    .collect(),
            },
        )
    }

    /// A cached scalar (e.g. a reference integral) named `name`, if present with
    /// this `fingerprint`.
    pub fn get_scalar(&self, name: &str, fingerprint: &str) -> Option<f64> {
        let text = std::fs::read_to_string(self.scalar_path(name)).ok()?;
        let v: serde_json::Value = serde_json::from_str(&text).ok()?;
        (v.get("fingerprint")?.as_str()? == fingerprint)
            .then(|| v.get("bits")?.as_u64().map(f64::from_bits))
            .flatten()
    }

    /// Stores a scalar atomically.
    pub fn put_scalar(&self, name: &str, fingerprint: &str, value: f64) -> Result<()> {
        write_json(
            &self.scalar_path(name),
            &serde_json::json!({
                "name": name,
                "fingerprint": fingerprint,
                "value": value,
                "bits": value.to_bits(),
            }),
        )
    }

    fn scalar_path(&self, name: &str) -> PathBuf {
        self.root
            .join("references")
            .join(format!("{}.json", sanitize(name)))
    }
}

/// Writes `value` as pretty JSON to `path` atomically, creating parent directories.
fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    if let Some(dir) = path.parent() {
        crate::output::ensure_dir(dir)?;
    }
    let text = serde_json::to_string(value).context("cannot serialize a cache entry")?;
    crate::output::write_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("nuld-eval-cache-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn entries_round_trip_bit_exactly_and_check_key_and_fingerprint() {
        let dir = scratch("entries");
        let cache = Cache::new(&dir);
        let key = CacheKey {
            figure: "fig5".into(),
            method: "owen-sobol".into(),
            target: "image:a/b.png".into(),
            n: 64,
            seed: 3,
        };
        assert_eq!(cache.get(&key, "fp"), None);
        // Values whose shortest decimal form is long or awkward.
        let values: Values = [
            ("a".to_string(), 0.1 + 0.2),
            ("b".to_string(), 1.0 / 3.0),
            ("c".to_string(), 5e-324),
            ("d".to_string(), 123456.789e-17),
        ]
        .into_iter()
        .collect();
        cache.put(&key, "fp", &values).unwrap();
        let back = cache.get(&key, "fp").unwrap();
        assert_eq!(back.len(), values.len());
        for (k, v) in &values {
            assert_eq!(back[k].to_bits(), v.to_bits(), "{k}");
        }
        // Another fingerprint, seed or N is a miss.
        assert_eq!(cache.get(&key, "other"), None);
        assert_eq!(
            cache.get(
                &CacheKey {
                    seed: 4,
                    ..key.clone()
                },
                "fp"
            ),
            None
        );
        assert_eq!(
            cache.get(
                &CacheKey {
                    n: 32,
                    ..key.clone()
                },
                "fp"
            ),
            None
        );
        // The path is file-name safe and nothing temporary is left.
        let path = cache.entry_path(&key);
        assert!(path.starts_with(&dir));
        assert!(path.to_string_lossy().contains("image_a_b.png"));
        let names: Vec<_> = std::fs::read_dir(path.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        // A corrupt entry is a miss, not an error.
        std::fs::write(&path, "{not json").unwrap();
        assert_eq!(cache.get(&key, "fp"), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn points_and_scalars_round_trip() {
        let dir = scratch("points");
        let cache = Cache::new(&dir);
        let pts = vec![
            DVec2::new(0.1, 0.7),
            DVec2::new(1.0 / 3.0, 2.0f64.sqrt() - 1.0),
        ];
        assert!(cache.get_points("g", 2, 9, "fp").is_none());
        cache.put_points("g", 9, "fp", &pts).unwrap();
        assert_eq!(cache.get_points("g", 2, 9, "fp").unwrap(), pts);
        assert!(cache.get_points("g", 2, 9, "other").is_none());
        assert!(cache.get_points("g", 2, 8, "fp").is_none());
        cache.put_scalar("ref", "v1", std::f64::consts::PI).unwrap();
        assert_eq!(cache.get_scalar("ref", "v1"), Some(std::f64::consts::PI));
        assert_eq!(cache.get_scalar("ref", "v2"), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
