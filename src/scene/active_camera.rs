//! The scene's active camera at a frame: Blender switches it at timeline markers bound
//! to cameras (`BKE_scene_camera_switch_find`, run by frame changes and by the render
//! pipeline before it syncs a frame).

use super::{quote, Scene};

impl Scene {
    /// The active camera object at `frame`. Among the markers bound to a camera that is
    /// not hidden from renders, the one at the latest frame not after `int(frame)` wins
    /// (the first listed of several on that frame); before every marker, the first
    /// listed at the earliest frame. Without such markers it is the exported
    /// `scene.camera`. A marker camera whose Disable in Renders is animated is an error
    /// naming it: Blender reads the flag as it stands when it switches, which depends on
    /// how the frame was reached.
    pub fn camera_at(&self, frame: f64) -> Result<Option<&str>, String> {
        let s = &self.file.scene;
        if s.camera_markers.is_empty() {
            return Ok(s.camera.as_deref());
        }
        // Blender truncates its scene time, whole frame plus subframe summed in single
        // precision, toward zero (`int(BKE_scene_ctime_get)`).
        let whole = frame.floor();
        let now = (whole as f32 + (frame - whole) as f32) as i32;
        let mut best: Option<(i32, &str)> = None;
        let mut first: Option<(i32, &str)> = None;
        for m in &s.camera_markers {
            if self.hidden_from_render(&m.camera)? {
                continue;
            }
            if m.frame <= now && best.is_none_or(|(f, _)| m.frame > f) {
                best = Some((m.frame, &m.camera));
                if m.frame == now {
                    break;
                }
            }
            if first.is_none_or(|(f, _)| m.frame < f) {
                first = Some((m.frame, &m.camera));
            }
        }
        Ok(best.or(first).map(|(_, c)| c).or(s.camera.as_deref()))
    }

    /// Whether a marker's camera object is disabled in renders (objects the export lacks
    /// are left to the caller's lookup, which names them).
    fn hidden_from_render(&self, name: &str) -> Result<bool, String> {
        let animated = self.file.animation.iter().any(|a| {
            a.id_type == "OBJECT"
                && a.id_name == name
                && a.fcurves
                    .iter()
                    .chain(&a.drivers)
                    .any(|fc| fc.data_path == "hide_render")
        });
        if animated {
            return Err(format!(
                "objects[{}]: its Disable in Renders (hide_render) is animated and a timeline \
                 marker binds it as the scene camera; Blender's camera switching reads the \
                 flag as it stands when the frame changes, which blendsynth does not follow",
                quote(name)
            ));
        }
        Ok(self
            .file
            .objects
            .iter()
            .any(|o| o.name == name && o.hide_render))
    }
}
