//! PLACEHOLDER (replaced by the exp branch's version at merge).
/// Summary.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Summary {
    /// n
    pub count: u64,
    /// mean
    pub mean: f64,
    /// p50
    pub p50: f64,
    /// p99
    pub p99: f64,
    /// min
    pub min: f64,
    /// max
    pub max: f64,
    /// std
    pub std: f64,
}
impl Summary {
    /// of
    pub fn of(v: &[f64]) -> Summary {
        if v.is_empty() { return Summary::default(); }
        let mut s = v.to_vec(); s.sort_by(|a, b| a.total_cmp(b));
        let n = s.len() as f64; let mean = s.iter().sum::<f64>() / n;
        let q = |p: f64| { let x = p * (n - 1.0); let i = x.floor() as usize; let j = (i + 1).min(s.len() - 1); s[i] + (s[j] - s[i]) * (x - i as f64) };
        Summary { count: s.len() as u64, mean, p50: q(0.5), p99: q(0.99), min: s[0], max: s[s.len()-1], std: (s.iter().map(|x| (x-mean).powi(2)).sum::<f64>() / n).sqrt() }
    }
}
