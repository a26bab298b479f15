// Generates a realistic WSL module for the compile benchmark (included by the bench and
// by tests/bench_input.rs).

/// A module of about `lines` lines: constants, globals, functions with arithmetic in
/// units, and procedures with motion, loops, branches, waits and handlers.
pub fn program(lines: usize) -> String {
    let mut s = String::with_capacity(lines * 40);
    s.push_str("global parts = 0;\nglobal station_free = true;\nglobal load = 0mm;\n");
    s.push_str("const home = joints(0deg, -30deg, 30deg, 0deg, 60deg, 0deg);\n");
    s.push_str("var done = 0;\nproc monitor() { log \"cycle \", cycle(); }\n");
    let mut n = 0;
    while s.lines().count() < lines.saturating_sub(30) {
        // Each block is 23 lines; counting lines once per block keeps this linear enough.
        s.push_str(&format!(
            "const p{n} = pose({x}mm, {y}mm, 300mm, 180deg, 0deg, {r}deg);
func lift{n}(p: pose, h: length) -> pose {{
    var z = p.z + h * 2 - 10mm;
    if z > 500mm {{ z = 500mm; }}
    return offset(p, 0mm, 0mm, z - p.z);
}}
proc cell{n}(count: int, gap: length) {{
    var total = 0;
    move_j home speed 50%;
    for i in 0..count {{
        var t = lift{n}(p{n}, gap + num(i) * 5mm);
        move_l t speed 250mm/s;
        if i mod 2 == 0 and station_free {{
            total += i;
        }} else {{
            total -= 1;
        }}
        delay 0.1s + 20ms * num(i);
    }}
    wait_until parts >= count timeout 5s;
    when parts >= count + 10 do monitor();
    parts = parts + total;
    done += 1;
    log \"cell {n} total \", total, \" at \", now();
}}
",
            x = 300 + n % 200,
            y = -200 + (n * 7) % 400,
            r = n % 90
        ));
        n += 1;
    }
    s.push_str("proc main() {\n");
    for i in 0..n.min(20) {
        s.push_str(&format!("    cell{i}(3, 10mm);\n"));
    }
    s.push_str("}\n");
    s
}
