//! Cancellation stops a bake with `Cancelled`, and progress names the stages.

mod common;
use common::*;
use penumbra::{BakeError, Progress};

#[test]
fn cancelled_bake_returns_cancelled() {
    let s = scene(
        vec![
            mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)]),
            mesh("Occ", vec![quad([0., 0., 1.], 0.4, 0.4, true)]),
        ],
        vec![area_light("L", quad([0., 0., 2.], 0.5, 0.5, false))],
        Default::default(),
    );
    let sc = penumbra::scene::validate(&s).unwrap();
    let p = Progress::new();
    p.cancel();
    assert_eq!(penumbra::bake(&sc, &p).unwrap_err(), BakeError::Cancelled);
    // A bake cancelled from another thread while it runs also ends cleanly.
    let p = std::sync::Arc::new(Progress::new());
    let q = p.clone();
    let h = std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_millis(1));
        q.cancel();
    });
    let r = penumbra::bake(&sc, &p);
    h.join().unwrap();
    assert!(matches!(r, Ok(_) | Err(BakeError::Cancelled)));
    let done = penumbra::bake(&sc, &Progress::new()).unwrap();
    assert!(done.stats.N_e > 0);
}
