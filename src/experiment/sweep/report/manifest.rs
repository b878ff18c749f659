//! manifest.toml: where the results came from (commit, files and their hashes, seeds, timing
//! settings, adapter, render plan).

use super::results::Results;

/// The manifest's text.
pub fn manifest(r: &Results) -> String {
    let s = r.spec;
    let a = r.adapter;
    let hash = |t: &str| format!("{:016x}", crate::fingerprint::fnv1a(t.as_bytes()));
    let experiment_text = std::fs::read_to_string(&s.path).unwrap_or_default();
    let q = |t: &str| format!("{t:?}");
    let list = |v: Vec<String>| format!("[{}]", v.join(", "));
    let mut m = String::from("# Provenance of the results in this folder.\n");
    m += &format!("git_commit = {}\n", q(&crate::output::git_commit()));
    m += &format!(
        "experiment = {}\nexperiment_fnv1a = {}\n",
        q(&s.path.display().to_string()),
        q(&hash(&experiment_text))
    );
    m += &format!(
        "scene = {}\nscene_fnv1a = {}\n",
        q(&s.scene_path.display().to_string()),
        q(&hash(&s.scene_text))
    );
    m += &format!(
        "runs = {}\nfailed_runs = {}\nresumed_groups = {}\nsweep_seconds = {:.1}\n",
        r.outcome.records.len(),
        r.outcome.failures,
        r.outcome.resumed,
        r.seconds
    );
    if let Some(rss) = r.peak_rss {
        m += &format!("peak_rss_bytes = {rss}\n");
    }
    m += &format!(
        "seeds = {}\n",
        list(s.axes.seeds.iter().map(|x| x.to_string()).collect())
    );
    m += &format!(
        "timing_warmup = {}\ntiming_repeats = {}\ntiming_order_seed = {}\n",
        s.timing.warmup,
        s.timing.repeats,
        crate::experiment::sweep::timing::ORDER_SEED
    );
    m += &format!(
        "ground_truth_samples = {}\nground_truth_seed = {}\n",
        s.ground_truth.samples,
        crate::experiment::sweep::reference::GROUND_TRUTH_SEED
    );
    m += &format!(
        "[adapter]\nbackend = {}\nname = {}\ndriver = {}\napi = {}\n",
        q(&a.backend),
        q(&a.name),
        q(&a.driver),
        q(&a.api)
    );
    if let Some(cap) = a.loop_cap {
        m += &format!("loop_iteration_cap = {cap}\n");
    }
    m += &format!("[plan]\nfirst_run = {}\n", q(r.outcome.plan.to_string().trim()));
    m
}
