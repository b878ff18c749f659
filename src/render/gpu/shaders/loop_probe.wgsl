// Counts the iterations two nested loops actually run in one invocation. The trip counts come
// from a buffer so no compiler can fold the loops away; an adapter that caps loop iterations
// (Mesa's llvmpipe: 65535 per invocation, nested loops counted together) reports fewer than
// outer x inner.

@group(0) @binding(0) var<storage, read_write> probe: array<u32>;

@compute @workgroup_size(1)
fn count_iterations() {
    let outer = probe[0];
    let inner = probe[1];
    var count = 0u;
    for (var i = 0u; i < outer; i++) {
        for (var j = 0u; j < inner; j++) {
            count += 1u;
        }
    }
    probe[2] = count;
}
