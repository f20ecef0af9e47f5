//! Shards of an index range: a run of many independent items (training rows, coverage truths,
//! depletion records) split into M strided parts that separate processes (Slurm array tasks)
//! run and a merge joins.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Shard K of M: indices offset + i with i % M == K (strided, so every shard sees the whole
/// sequence and takes about the same time).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, 0 <= k < m.
    pub k: u64,
    /// Number of shards.
    pub m: u64,
}

impl Shard {
    /// The whole range in one shard.
    pub const WHOLE: Shard = Shard { k: 0, m: 1 };

    /// Parses `K/M`; the error is an [`Error::Shard`] naming the text.
    ///
    /// ```
    /// use hpge_foundation::Shard;
    /// let s = Shard::parse("1/4")?;
    /// // Strided: shard 1 of 4 takes every fourth index from offset + 1.
    /// assert_eq!(s.indices(100, 10).collect::<Vec<_>>(), [101, 105, 109]);
    /// assert!(Shard::parse("4/4").is_err());
    /// assert!(Shard::parse("1of4").is_err());
    /// # Ok::<(), hpge_foundation::Error>(())
    /// ```
    pub fn parse(s: &str) -> Result<Shard> {
        let bad = |message: String| Error::Shard {
            text: s.to_string(),
            message,
        };
        let (k, m) = s
            .split_once('/')
            .ok_or_else(|| bad("expected K/M, e.g. 0/4".to_string()))?;
        let num = |t: &str| {
            t.trim()
                .parse::<u64>()
                .map_err(|e| bad(format!("`{t}` is not a whole number ({e})")))
        };
        let (k, m) = (num(k)?, num(m)?);
        if m == 0 || k >= m {
            return Err(bad("need 0 <= K < M".to_string()));
        }
        Ok(Shard { k, m })
    }

    /// The indices of this shard in [offset, offset + n).
    pub fn indices(&self, offset: u64, n: u64) -> impl Iterator<Item = u64> + '_ {
        let (k, m) = (self.k, self.m);
        (0..n).filter(move |i| i % m == k).map(move |i| offset + i)
    }
}
