//! What a solve plugs into the solver besides its settings ([`RunHooks`]): the reference to
//! measure against (`--reference`), per-light channels (`--per-light`), the checkpoint sink
//! (`--checkpoint`), the state to resume from (`--resume`) and the Ctrl-C flag.

use super::SolveJob;
use crate::export::{patches, solution, write_atomic};
use crate::model::Model;
use crate::solve::checkpoint::{self, Checkpoint};
use crate::solve::driver::{Saved, Sink};
use crate::solve::{lights, RunHooks};
use crate::Error;
use std::sync::Arc;

/// Builds the hooks of `job` for `model`, logging what they hold.
pub fn build(job: &SolveJob, model: &Model, log: &mut impl FnMut(&str)) -> Result<RunHooks, Error> {
    let (scene, m) = (&model.scene, &model.mesh);
    let mut hooks = RunHooks {
        interrupt: job.interrupt.clone(),
        ..RunHooks::default()
    };
    if let Some(by) = job.settings.per_light {
        let mut g = lights::groups(scene, m, by);
        // The sky (with the ground glow) and the sun get channels of their own.
        if let Some(spec) = &job.settings.solve.sky {
            g.names.push(lights::SKY_CHANNEL.to_string());
            if spec.sun.is_some() {
                g.names.push(lights::SUN_CHANNEL.to_string());
            }
        }
        // Each luminaire group too (a group named as an emitting material shares its channel).
        for l in &scene.luminaires {
            if g.channel(&l.group).is_none() {
                g.names.push(l.group.clone());
            }
        }
        log(&format!(
            "per-light channels: {} ({})",
            g.len(),
            g.names.join(", ")
        ));
        hooks.light_groups = Some(Arc::new(g));
    }
    if let Some(path) = &job.reference {
        hooks.reference = Some(Arc::new(patches::read_reference(path, m)?));
    }
    if job.checkpoint.is_none() && job.resume.is_none() {
        return Ok(hooks);
    }
    let hash = solution::scene_hash(scene, m.patch_size, job.settings.mesh.two_sided);
    let key = job.settings.checkpoint_key(hash, m.patch_size);
    if let Some(path) = &job.checkpoint {
        let path = path.clone();
        let key = key.clone();
        hooks.checkpoint = Some(Sink {
            every: std::time::Duration::from_secs_f64(job.checkpoint_every),
            write: Arc::new(move |run: &Saved| {
                let bytes = checkpoint::to_bytes(&key, run);
                write_atomic(&path, |w| w.write_all(&bytes)).map_err(|e| e.to_string())
            }),
        });
    }
    if let Some(path) = &job.resume {
        let what = path.display().to_string();
        let bytes = std::fs::read(path)
            .map_err(|e| Error::Invalid(format!("--resume {what}: cannot read it ({e})")))?;
        let ckpt = Checkpoint::from_bytes(&what, &bytes).map_err(Error::Invalid)?;
        ckpt.check_key(&what, &key).map_err(Error::Invalid)?;
        log(&format!(
            "resuming from {what}: {} shots, {:.1} s done",
            ckpt.run.shots, ckpt.run.elapsed
        ));
        hooks.resume = Some(Arc::new(ckpt.run));
    }
    Ok(hooks)
}
