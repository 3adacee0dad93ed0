//! A model: a loaded scene cut into patches, and the intersector a command asks for. The
//! load → mesh → intersector sequence that every command runs (solve, info, compare,
//! reference, the benchmarks, the cross-check, the sweep), written once, with its checks and
//! its errors.

use crate::intersect::select::{self, AnyIntersector, IntersectorKind, Selection};
use crate::intersect::Intersector;
use crate::mesh::{self, Mesh, MeshOptions};
use crate::scene::{LoadOptions, Scene, SceneError, SceneSource};
use crate::solve::{self, MethodKind, RunHooks, Solution, SolveSettings, TracePoint};
use crate::Error;

/// A scene and its patches.
pub struct Model {
    pub scene: Scene,
    pub mesh: Mesh,
}

impl Model {
    /// Loads the scene named by `source` and cuts it into patches (after checking the mesh
    /// settings).
    pub fn load(
        source: &SceneSource,
        load: &LoadOptions,
        mesh: &MeshOptions,
    ) -> Result<Model, Error> {
        mesh.check()?;
        Model::from_scene(source.load(load)?, mesh)
    }

    /// Cuts an already loaded scene into patches, refusing a patch size that would make far
    /// too many.
    pub fn from_scene(scene: Scene, opts: &MeshOptions) -> Result<Model, Error> {
        opts.check()?;
        let mesh = mesh::try_build(&scene, opts).map_err(|message| SceneError {
            path: scene.name.clone(),
            message,
        })?;
        Ok(Model { scene, mesh })
    }

    /// One line: the scene's name, its patch count and the patch size.
    pub fn describe(&self) -> String {
        format!(
            "{}: {} patches at {} m",
            self.scene.name,
            self.mesh.patches.len(),
            self.mesh.patch_size
        )
    }

    /// Builds the intersector of `kind` (resolving `auto` for this mesh), and says why.
    pub fn intersector(&self, kind: IntersectorKind) -> Result<(AnyIntersector, Selection), Error> {
        Ok(select::select(&self.mesh, kind)?)
    }

    /// The intersector `method` needs: none for the methods that cast no rays (a scene builds
    /// only what it needs).
    pub fn intersector_for(
        &self,
        method: MethodKind,
        kind: IntersectorKind,
    ) -> Result<Option<(AnyIntersector, Selection)>, Error> {
        if method.casts_rays() {
            self.intersector(kind).map(Some)
        } else {
            Ok(None)
        }
    }

    /// Solves by `settings.method` (checked first), casting rays through `isect` where the
    /// method needs them; the error names the scene.
    pub fn solve<I: Intersector>(
        &self,
        isect: Option<&I>,
        settings: &SolveSettings,
        hooks: &RunHooks,
        on_trace: impl FnMut(&TracePoint),
    ) -> Result<Solution, Error> {
        settings.check()?;
        solve::run(
            &self.mesh,
            &self.scene.materials,
            isect,
            settings,
            hooks,
            on_trace,
        )
        .map_err(|source| Error::Solve {
            scene: self.scene.name.clone(),
            source,
        })
    }

    /// Finds the sides of the mesh's surfaces that no light can reach ([`crate::mesh::Hidden`],
    /// `intersect::hidden`), with `isect` built over this mesh.
    pub fn find_hidden<I: Intersector>(&mut self, isect: &I, seed: u64) {
        let materials = &self.scene.materials;
        let open: Vec<bool> = (self.mesh.patches.iter())
            .map(|p| materials[p.material as usize].transmittance > 0.0)
            .collect();
        self.mesh.hidden = crate::intersect::hidden::find(&self.mesh, isect, &open, seed);
    }

    /// Scalar flux the lights emit (W): what a solve's progress is measured against.
    pub fn emitted_flux(&self) -> f64 {
        let materials = &self.scene.materials;
        self.mesh
            .patches
            .iter()
            .map(|p| solve::scalar(&materials[p.material as usize].emission()) * p.area)
            .sum()
    }
}
