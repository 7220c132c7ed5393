//! `render::control`: a render followed and stopped from another thread renders the same
//! bits when not stopped, reports its progress up to the planned total, and returns the
//! cancelled error (not a partial image) when stopped, from before or during the render.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use blendsynth::render::control::Control;
use blendsynth::render::{render, render_controlled, RenderOptions};
use blendsynth::scene::Scene;

fn scene() -> Scene {
    Scene::load(&common::repo().join("fixtures/render/scenes/diffuse_point")).unwrap()
}

#[test]
fn uncancelled_render_is_unchanged_and_reports_progress() {
    let s = scene();
    let opts = RenderOptions {
        samples: Some(4),
        resolution: Some((40, 24)),
        threads: Some(2),
        ..Default::default()
    };
    let plain = render(&s, &opts).unwrap();
    let c = Control::new();
    let followed = render_controlled(&s, &opts, &[], Some(&c)).unwrap();
    assert_eq!(plain.color, followed.color);
    assert_eq!(plain.passes.instance_id, followed.passes.instance_id);
    assert_eq!(c.progress(), (40 * 24 * 4, 40 * 24 * 4));
}

#[test]
fn cancelled_render_stops_with_the_cancelled_error() {
    let s = scene();
    // Cancelled before it starts: no pixel is rendered.
    let flag = Arc::new(AtomicBool::new(true));
    let c = Control::with_flag(flag.clone());
    let opts = RenderOptions {
        samples: Some(100_000),
        threshold: Some(0.0),
        resolution: Some((64, 64)),
        threads: Some(2),
        ..Default::default()
    };
    let e = render_controlled(&s, &opts, &[], Some(&c)).unwrap_err();
    assert!(e.is_cancelled(), "{e}");
    assert_eq!(c.progress().0, 0);
    // Cancelled from another thread while it runs (100k samples would take minutes).
    flag.store(false, Ordering::Relaxed);
    let c = Arc::new(Control::with_flag(flag.clone()));
    let stopper = {
        let flag = flag.clone();
        std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(300));
            flag.store(true, Ordering::Relaxed);
        })
    };
    let t = std::time::Instant::now();
    let e = render_controlled(&s, &opts, &[], Some(&c)).unwrap_err();
    stopper.join().unwrap();
    assert!(e.is_cancelled(), "{e}");
    assert!(c.is_cancelled());
    assert!(t.elapsed().as_secs() < 30, "{:?}", t.elapsed());
}
