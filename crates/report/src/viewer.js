// The report's timeline and 3D view (see viewer.rs for the data it reads).
//
// One simulated time `now` (ns) drives everything: the clock, the slider, the cursor over
// the Gantt chart and, with WebGL, the 3D view. The Gantt chart, the event rows and the
// URL fragment `#t=SECONDS` set it; Play advances it at the chosen speed. The page draws
// only when something changed (time, camera, size), so a paused report costs nothing.
(function () {
  "use strict";
  var timeline = document.getElementById("timeline");
  if (!timeline) return;
  var END = Number(timeline.dataset.endNs) || 0;
  var play = document.getElementById("play"), speed = document.getElementById("speed"),
      slider = document.getElementById("slider"), clock = document.getElementById("clock");
  var gantt = document.getElementById("gantt"), cursor = document.getElementById("gantt-cursor");
  var now = 0, playing = false, last = 0, view = null, lastWidgets = -1e9;

  // `playback`: called by Play, which redraws the 3D view every frame but the clock,
  // slider and Gantt cursor ten times a second (repainting them is most of a software
  // renderer's frame).
  function setTime(ns, playback) {
    now = Math.min(Math.max(Number(ns) || 0, 0), END);
    if (view) view.show(now);
    var t = performance.now();
    if (playback && t - lastWidgets < 100) return;
    lastWidgets = t;
    slider.value = String(now / 1e9);
    clock.textContent = (now / 1e9).toFixed(3) + " s";
    if (gantt && cursor) {
      var x = Number(gantt.dataset.left) + Number(gantt.dataset.width) * (END > 0 ? now / END : 0);
      cursor.setAttribute("x1", x.toFixed(2));
      cursor.setAttribute("x2", x.toFixed(2));
    }
  }
  function pause() {
    if (!playing) return;
    if (view) view.playing(false);
    playing = false;
    play.textContent = "Play";
    setTime(now);
  }
  function tick(stamp) {
    if (!playing) return;
    var dt = Math.min(stamp - last, 100);
    last = stamp;
    setTime(now + dt * 1e6 * Number(speed.value), true);
    if (now >= END) pause(); else requestAnimationFrame(tick);
  }
  play.addEventListener("click", function () {
    if (playing) { pause(); return; }
    if (now >= END) setTime(0);
    playing = true;
    if (view) view.playing(true);
    play.textContent = "Pause";
    last = performance.now();
    requestAnimationFrame(tick);
  });
  slider.addEventListener("input", function () { pause(); setTime(Number(slider.value) * 1e9); });
  if (gantt) {
    gantt.addEventListener("click", function (e) {
      var m = gantt.getScreenCTM();
      if (!m) return;
      var pt = gantt.createSVGPoint();
      pt.x = e.clientX; pt.y = e.clientY;
      var x = pt.matrixTransform(m.inverse()).x, left = Number(gantt.dataset.left),
          width = Number(gantt.dataset.width);
      if (x < left || x > left + width) return;
      pause();
      setTime((x - left) / width * END);
    });
  }
  // Event, collision and issue rows carry their time.
  document.addEventListener("click", function (e) {
    var row = e.target instanceof Element ? e.target.closest("tr[data-t]") : null;
    if (!row) return;
    pause();
    setTime(Number(row.dataset.t));
    var stage = document.getElementById("stage");
    if (stage && stage.getBoundingClientRect().bottom < 0) stage.scrollIntoView();
  });
  function fromHash() {
    var m = /(?:^#|&)t=([0-9]*\.?[0-9]+)/.exec(location.hash);
    if (m) { pause(); setTime(Number(m[1]) * 1e9); }
  }
  window.addEventListener("hashchange", fromHash);
  // Keys, outside text fields: space plays or pauses, the arrows step 1/30 s (with Shift
  // 1 s), Home and End go to the ends.
  document.addEventListener("keydown", function (e) {
    var t = e.target;
    if (e.ctrlKey || e.metaKey || e.altKey || (t instanceof Element && t.closest("input, select, textarea, button"))) return;
    var step = e.shiftKey ? 1e9 : 1e9 / 30;
    if (e.key === " ") play.click();
    else if (e.key === "ArrowRight") { pause(); setTime(now + step); }
    else if (e.key === "ArrowLeft") { pause(); setTime(now - step); }
    else if (e.key === "Home") { pause(); setTime(0); }
    else if (e.key === "End") { pause(); setTime(END); }
    else return;
    e.preventDefault();
  });

  var dataEl = document.getElementById("vworks-playback");
  var canvas = document.getElementById("canvas3d");
  var note = document.getElementById("view-note");
  if (dataEl && canvas && typeof THREE !== "undefined") {
    var gl = context(canvas, true);
    // A software renderer (no GPU) draws four arms at 60 frames a second only without
    // multisampling, which costs it three times the frame: such a browser gets a canvas
    // without it.
    var info = gl && gl.getExtension("WEBGL_debug_renderer_info");
    var software = info && /SwiftShader|llvmpipe|softpipe|Software/i.test(
      String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)));
    if (software) {
      var plain = canvas.cloneNode(false);
      canvas.replaceWith(plain);
      canvas = plain;
      gl = context(canvas, false);
    }
    if (!gl) {
      canvas.hidden = true;
      document.getElementById("view-tools").hidden = true;
      document.getElementById("stage").classList.add("empty");
      note.hidden = false;
      note.textContent = "No 3D view: this browser has no WebGL 2. The timeline, the Gantt chart and the tables below are complete.";
    } else {
      view = makeView(JSON.parse(dataEl.textContent), canvas, gl, software);
    }
  }
  window.vworksView = {
    setTime: function (ns) { pause(); setTime(ns); },
    time: function () { return now; },
    end: END,
    view: view
  };
  setTime(0);
  fromHash();

  function context(canvas, antialias) {
    try {
      return canvas.getContext("webgl2", { antialias: antialias, preserveDrawingBuffer: true });
    } catch (err) { return null; }
  }
  function bytes(b64) {
    var s = atob(b64), out = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
    return out.buffer;
  }
  function floats(b64) { return new Float32Array(bytes(b64)); }

  function makeView(data, canvas, gl, software) {
    var T = THREE;
    var renderer = new T.WebGLRenderer({ canvas: canvas, context: gl });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setClearColor(0xeef1f4);
    var scene = new T.Scene();
    var camera = new T.PerspectiveCamera(40, 1, 0.01, 500);
    camera.up.set(0, 0, 1);
    scene.add(new T.HemisphereLight(0xffffff, 0x8a8f96, 2.2));
    var sun = new T.DirectionalLight(0xffffff, 1.6);
    sun.position.set(3, -2, 6);
    scene.add(sun);

    // The frame tree, each frame at its first pose.
    var first = floats(data.first), frames = data.frames.map(function (name, i) {
      var o = new T.Object3D();
      o.name = name;
      o.position.set(first[7 * i], first[7 * i + 1], first[7 * i + 2]);
      o.quaternion.set(first[7 * i + 3], first[7 * i + 4], first[7 * i + 5], first[7 * i + 6]);
      return o;
    });
    var index = {};
    data.frames.forEach(function (name, i) { index[name] = i; });
    frames.forEach(function (o, i) {
      var p = data.parents[i];
      (p >= 0 && frames[p] ? frames[p] : scene).add(o);
    });

    function indexedGeometry(vertices, indices) {
      var g = new T.BufferGeometry();
      g.setAttribute("position", new T.BufferAttribute(floats(vertices), 3));
      g.setIndex(new T.BufferAttribute(new Uint32Array(bytes(indices)), 1));
      return g;
    }
    // With a software renderer, each hull's [exact, coarse, mesh]: playback draws the
    // coarse ones (see `viewer.rs`, `coarse`), a paused view the exact ones.
    var coarse = [], coarseOn = false;
    function useCoarse(on) {
      if (on === coarseOn) return;
      coarseOn = on;
      coarse.forEach(function (c) { c[2].geometry = c[on ? 1 : 0]; });
    }
    // The bodies, in their colours, attached to their frames. Each frame has a smooth and
    // a flat material (hulls: flat faces from shared vertices), recoloured together.
    var materials = {}, meshes = [], own = {};
    data.bodies.forEach(function (b) {
      var parent = index[b.frame] !== undefined ? frames[index[b.frame]] : scene;
      if (!materials[b.frame]) {
        materials[b.frame] = [new T.MeshLambertMaterial(), new T.MeshLambertMaterial({ flatShading: true })];
        materials[b.frame].forEach(function (m) {
          m.color.setRGB(b.colour[0], b.colour[1], b.colour[2], T.SRGBColorSpace);
        });
        own[b.frame] = b.colour;
      }
      b.shapes.forEach(function (s) {
        var g;
        if (s.kind === "box") g = new T.BoxGeometry(s.size[0], s.size[1], s.size[2]);
        else if (s.kind === "sphere") g = new T.SphereGeometry(s.size[0] / 2, 16, 12);
        else if (s.kind === "capsule") {
          g = new T.CapsuleGeometry(s.size[0] / 2, s.size[2], 4, 16);
          g.rotateX(Math.PI / 2);
        }
        else if (s.kind === "cylinder") {
          g = new T.CylinderGeometry(s.size[0] / 2, s.size[0] / 2, s.size[2], 20);
          g.rotateX(Math.PI / 2); // three's cylinders stand along y, the log's along z
        } else if (s.kind === "mesh") {
          g = indexedGeometry(s.vertices, s.indices);
          if (software) coarse.push([g, indexedGeometry(s.coarse_vertices, s.coarse_indices)]);
        } else return;
        var m = new T.Mesh(g, materials[b.frame][s.kind === "mesh" ? 1 : 0]);
        if (software && s.kind === "mesh") coarse[coarse.length - 1].push(m);
        m.position.set(s.pose[0], s.pose[1], s.pose[2]);
        m.quaternion.set(s.pose[3], s.pose[4], s.pose[5], s.pose[6]);
        m.userData.label = b.label;
        parent.add(m);
        meshes.push(m);
      });
    });

    // Colour changes from /scene, per frame, in time order.
    var changes = {};
    data.colours.forEach(function (c) { (changes[c[1]] = changes[c[1]] || []).push(c); });
    var shown = {};

    // The samples.
    var times = data.times, values = floats(data.values), stride = data.stride;
    var tracks = data.tracks.map(function (t) {
      return {
        obj: frames[t.frame], kind: t.kind,
        t0: new T.Vector3(t.base[0], t.base[1], t.base[2]),
        q0: new T.Quaternion(t.base[3], t.base[4], t.base[5], t.base[6]),
        axis: new T.Vector3(t.axis[0], t.axis[1], t.axis[2]),
        width: t.kind === "free" ? 7 : 1
      };
    });
    var turn = new T.Quaternion(), qa = new T.Quaternion(), qb = new T.Quaternion();
    function sampleAt(ns) {
      var lo = 0, hi = times.length - 1;
      if (ns <= times[0]) return [0, 0];
      if (ns >= times[hi]) return [hi, 0];
      while (hi - lo > 1) {
        var mid = (lo + hi) >> 1;
        if (times[mid] <= ns) lo = mid; else hi = mid;
      }
      return [lo, (ns - times[lo]) / (times[lo + 1] - times[lo])];
    }
    function pose(ns) {
      var s = sampleAt(ns), k = s[0], f = s[1], at = k * stride, next = f > 0 ? at + stride : at;
      tracks.forEach(function (t) {
        if (t.kind === "free") {
          t.obj.position.set(values[at] + f * (values[next] - values[at]),
                             values[at + 1] + f * (values[next + 1] - values[at + 1]),
                             values[at + 2] + f * (values[next + 2] - values[at + 2]));
          qa.set(values[at + 3], values[at + 4], values[at + 5], values[at + 6]);
          qb.set(values[next + 3], values[next + 4], values[next + 5], values[next + 6]);
          t.obj.quaternion.slerpQuaternions(qa, qb, f);
        } else {
          var v = values[at] + f * (values[next] - values[at]);
          if (t.kind === "revolute") {
            t.obj.position.copy(t.t0);
            t.obj.quaternion.copy(t.q0).multiply(turn.setFromAxisAngle(t.axis, v));
          } else {
            t.obj.position.copy(t.axis).multiplyScalar(v).applyQuaternion(t.q0).add(t.t0);
            t.obj.quaternion.copy(t.q0);
          }
        }
        at += t.width;
        next += t.width;
      });
    }
    function colourAt(ns) {
      Object.keys(changes).forEach(function (frame) {
        var c = own[frame], list = changes[frame];
        for (var i = 0; i < list.length && list[i][0] <= ns; i++) c = list[i].slice(2);
        if (!c || !materials[frame] || shown[frame] === c) return;
        shown[frame] = c;
        materials[frame].forEach(function (m) { m.color.setRGB(c[0], c[1], c[2], T.SRGBColorSpace); });
      });
    }

    // Floor grid and axes, sized to the cell.
    pose(0);
    scene.updateMatrixWorld(true);
    var box = new T.Box3();
    meshes.forEach(function (m) { box.expandByObject(m); });
    if (box.isEmpty()) box.set(new T.Vector3(-1, -1, 0), new T.Vector3(1, 1, 1));
    var centre = box.getCenter(new T.Vector3()), size = box.getSize(new T.Vector3());
    var extent = Math.max(size.x, size.y, size.z, 0.5);
    var cells = Math.ceil((Math.max(size.x, size.y) + 1) / 0.5 / 2) * 2;
    var grid = new T.GridHelper(cells * 0.5, cells, 0x9aa3ad, 0xc9d0d7);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(Math.round(centre.x * 2) / 2, Math.round(centre.y * 2) / 2, 0);
    scene.add(grid);
    scene.add(new T.AxesHelper(Math.min(0.5, extent / 3)));
    camera.near = extent / 200;
    camera.far = extent * 50;
    var home = {
      target: centre.clone(),
      position: centre.clone().add(new T.Vector3(1.1, -1.5, 0.9).normalize().multiplyScalar(extent * 1.9))
    };
    var controls = new T.OrbitControls(camera, canvas);
    function resetView() {
      camera.position.copy(home.position);
      controls.target.copy(home.target);
      controls.update();
      request();
    }

    // TCP trails: each robot's TCP in the world at every sample, computed when first shown.
    var trails = null, trailOn = false, palette = [0x1f77b4, 0x2ca02c, 0x9467bd, 0x17becf, 0x8c564b, 0xe377c2];
    function makeTrails() {
      var tcps = data.tcps.map(function (name) { return frames[index[name]]; });
      var points = tcps.map(function () { return new Float32Array(times.length * 3); });
      var p = new T.Vector3();
      for (var k = 0; k < times.length; k++) {
        pose(times[k]);
        scene.updateMatrixWorld(true);
        tcps.forEach(function (o, r) { o.getWorldPosition(p); points[r].set([p.x, p.y, p.z], 3 * k); });
      }
      shownAt = -1; // the frames are at the last sample now: `show` poses them again
      return tcps.map(function (o, r) {
        var g = new T.BufferGeometry();
        g.setAttribute("position", new T.BufferAttribute(points[r], 3));
        var line = new T.Line(g, new T.LineBasicMaterial({ color: palette[r % palette.length] }));
        scene.add(line);
        return line;
      });
    }
    document.getElementById("trail").addEventListener("change", function (e) {
      trailOn = e.target.checked;
      if (trailOn && !trails) trails = makeTrails();
      show(now);
    });

    var pending = false, shownAt = -1, drawn = 0;
    function draw() {
      pending = false;
      drawn++;
      var w = canvas.clientWidth, h = canvas.clientHeight;
      if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) || canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
        renderer.setSize(w, h, false);
        camera.aspect = w / Math.max(h, 1);
        camera.updateProjectionMatrix();
      }
      renderer.render(scene, camera);
    }
    function request() {
      if (!pending) { pending = true; requestAnimationFrame(draw); }
    }
    function show(ns) {
      if (ns !== shownAt) {
        pose(ns);
        colourAt(ns);
        shownAt = ns;
      }
      if (trails) {
        var k = sampleAt(ns)[0] + 1;
        trails.forEach(function (l) { l.visible = trailOn; l.geometry.setDrawRange(0, k); });
      }
      request();
    }

    // Names on hover.
    var tip = document.getElementById("tip"), ray = new T.Raycaster(), ndc = new T.Vector2();
    canvas.addEventListener("pointermove", function (e) {
      var r = canvas.getBoundingClientRect();
      ndc.set((e.clientX - r.left) / r.width * 2 - 1, -(e.clientY - r.top) / r.height * 2 + 1);
      ray.setFromCamera(ndc, camera);
      var hit = ray.intersectObjects(meshes, false)[0];
      tip.hidden = !hit;
      if (hit) {
        tip.textContent = hit.object.userData.label;
        tip.style.left = (e.clientX - r.left + 14) + "px";
        tip.style.top = (e.clientY - r.top + 10) + "px";
      }
    });
    canvas.addEventListener("pointerleave", function () { tip.hidden = true; });
    controls.addEventListener("change", request);
    document.getElementById("reset-view").addEventListener("click", resetView);
    window.addEventListener("resize", request);

    camera.position.copy(home.position);
    controls.target.copy(home.target);
    controls.update();
    // The first frame is drawn at once (not on the next animation frame), and timed.
    show(0);
    draw();
    renderer.getContext().finish();
    var firstFrameMs = performance.now();
    canvas.dataset.firstFrameMs = firstFrameMs.toFixed(1);

    return {
      show: show,
      /// Playing or paused (a software renderer draws coarse hulls while playing).
      playing: function (on) { useCoarse(on); if (!on) request(); },
      firstFrameMs: firstFrameMs,
      /// The camera as drawn: view and projection matrices (column-major) and the
      /// canvas's place on the page (CSS pixels), to project points as the page does.
      camera: function () {
        draw();
        var r = canvas.getBoundingClientRect();
        return {
          view: camera.matrixWorldInverse.elements.slice(),
          projection: camera.projectionMatrix.elements.slice(),
          rect: { left: r.left, top: r.top, width: r.width, height: r.height }
        };
      },
      /// Draws `n` frames of playback, `step` ns apart, synchronously; returns the mean
      /// milliseconds per frame (pose, colours, render, and reading a pixel back, which
      /// waits until the frame is drawn).
      benchmark: function (n, step) {
        var gl = renderer.getContext(), pixel = new Uint8Array(4), start = performance.now();
        for (var i = 0; i < n; i++) {
          show((i * step) % (END + 1));
          draw();
          gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel); // waits for the frame
        }
        return (performance.now() - start) / n;
      },
      /// A frame's pose in the world as shown: [x, y, z, qx, qy, qz, qw].
      worldPose: function (name) {
        var o = frames[index[name]];
        if (!o) return null;
        scene.updateMatrixWorld(true);
        var p = new T.Vector3(), q = new T.Quaternion(), s = new T.Vector3();
        o.matrixWorld.decompose(p, q, s);
        return [p.x, p.y, p.z, q.x, q.y, q.z, q.w];
      },
      /// TCP trails made so far (one per robot once the box is ticked).
      trails: function () { return trails ? trails.length : 0; },
      /// Frames drawn so far (to measure the frame rate of real playback).
      drawn: function () { return drawn; },
      software: !!software,
      bodies: meshes.length
    };
  }
})();
