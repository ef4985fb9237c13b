//! The same scene gives bit-identical output on 1 and on several threads.

mod common;
use common::*;

#[test]
fn one_and_four_threads_agree_bit_for_bit() {
    let mut meshes = vec![mesh("Floor", vec![quad([0., 0., 0.], 2., 2., true)])];
    meshes.push(mesh("Box", cuboid([-0.3, -0.2, 0.0], [0.3, 0.4, 0.5])));
    meshes.push(mesh("Ball", uv_sphere([0.8, 0.6, 0.9], 0.3, 12, 8)));
    meshes.push(mesh("Panel", vec![quad([-0.7, 0.5, 1.1], 0.3, 0.2, false)]));
    // Facing up over the bulb: lit on its back, which shoots down (indirect/back.rs).
    meshes.push(mesh("Shade", vec![quad([-1.0, -1.0, 1.7], 0.4, 0.4, true)]));
    let lights = vec![
        area_light("Key", quad([0.5, 0.3, 2.0], 0.3, 0.2, false)),
        point_light("Bulb", [-1.0, -1.0, 1.5]),
    ];
    let mut s = scene(meshes, lights, Default::default());
    let mut out = Vec::new();
    let mut counts = Vec::new();
    for threads in [1, 4] {
        s.settings.threads = Some(threads);
        let b = bake(&s);
        out.push(serde_json::to_string(&b.meshes).unwrap());
        let st = &b.stats;
        counts.push([st.N_links, st.rays, st.N_hidden, st.gather_rays]);
    }
    assert_eq!(out[0], out[1]);
    // The work is the same too: links, refinement's rays and the final gather's.
    assert_eq!(counts[0], counts[1]);
    assert!(counts[0][1] > 0 && counts[0][3] > 0, "{:?}", counts[0]);
}
