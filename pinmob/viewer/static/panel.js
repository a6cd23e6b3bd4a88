/* pinmob's information panel over meshcat's 3D view, and the labels of the glyphs.
 *
 * pinmob.install(viewer) makes the meshcat viewer understand one more command, "pinmob_panel", whose
 * "document" (built by pinmob/viewer/panel.py) says what the page shows in words: the mechanism and
 * configuration, the platform's DoF and motion type, one row per free motion (kind, direction, axis point
 * in world coordinates, pitch, how far its clip went and why it stopped), the singularity class, the whole
 * mechanism's DoF, the constraint wrenches, a legend and toggles; with a scan's workspace drawn, its counts and
 * colour scale (distance to singularity) with the marks. Clicking a row (or a label) plays that
 * motion's clip and highlights its glyph. Labels are HTML boxes placed every frame at the screen projection
 * of each glyph's anchor (a world point), pushed apart where they would overlap.
 */
(function () {
  "use strict";
  const pinmob = (window.pinmob = window.pinmob || {});
  const DIM = 0.22; // opacity of the glyphs not selected

  function fmt(x, digits) {
    if (x === null || x === undefined) return "–";
    const v = Number(Number(x).toPrecision(digits || 4));
    return Object.is(v, -0) || v === 0 ? "0" : String(v);
  }
  function vec(a) {
    return a ? "(" + a.map((x) => fmt(x)).join(", ") + ")" : "–";
  }
  function el(tag, attrs, children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "text") node.textContent = v;
      else if (k === "class") node.className = v;
      else node.setAttribute(k, v);
    }
    for (const child of children || []) node.appendChild(typeof child === "string" ? document.createTextNode(child) : child);
    return node;
  }

  pinmob.install = function (viewer) {
    const handle = viewer.handle_command.bind(viewer);
    viewer.handle_command = function (cmd) {
      if (cmd.type === "pinmob_panel") {
        pinmob.show(viewer, cmd.document);
        viewer.set_dirty();
        return;
      }
      handle(cmd);
    };
  };

  function glyphObject(viewer, glyph) {
    const node = viewer.scene_tree.find(glyph.path.concat(["<object>"]));
    return node && node.object && node.object.material ? node.object : null;
  }

  function setVisible(viewer, path, visible) {
    viewer.scene_tree.find(path).set_property("visible", visible);
    viewer.set_dirty();
  }

  pinmob.select = function (label) {
    const state = pinmob.state;
    if (!state || !(label in state.doc.clips)) return;
    const { viewer, doc } = state;
    state.selected = label;
    viewer.handle_command({
      type: "set_animation",
      animations: JSON.parse(JSON.stringify(doc.clips[label])),
      options: { play: true, repetitions: Infinity },
    });
    for (const glyph of doc.glyphs) {
      if (glyph.group !== "motion") continue;
      const obj = glyphObject(viewer, glyph);
      if (obj) {
        if (obj.userData.pinmobOpacity === undefined) obj.userData.pinmobOpacity = obj.material.opacity; // as drawn
        obj.material.transparent = true;
        obj.material.opacity = obj.userData.pinmobOpacity * (glyph.label === label ? 1.0 : DIM);
        obj.material.needsUpdate = true;
      }
    }
    for (const row of state.panel.querySelectorAll("tr.pinmob-motion")) {
      row.classList.toggle("selected", row.dataset.label === label);
    }
    for (const box of state.labels) {
      if (box.glyph.group === "motion") {
        box.node.classList.toggle("selected", box.glyph.label === label);
        box.node.classList.toggle("dimmed", box.glyph.label !== label);
      }
    }
    const row = doc.motions.find((m) => m.label === label);
    const playing = state.panel.querySelector(".pinmob-playing");
    playing.textContent = "Playing " + label + " (" + row.kind_word + "): " + row.clip_text + (row.why.length ? " — " + row.why.join("; ") : "");
    playing.classList.toggle("still", row.status !== "full");
    viewer.set_dirty();
  };

  function clipCell(m) {
    if (m.status === "static") return "not followed";
    if (m.status === "still") return "stays still";
    if (m.status === "full") return "±" + fmt(m.amplitude, 3) + " " + m.unit;
    return "+" + fmt(m.reached[0], 3) + " / −" + fmt(m.reached[1], 3) + " " + m.unit;
  }

  function motionTable(doc) {
    const verdicts = doc.motions.some((m) => m.verdict);
    const head = ["motion", "kind", "direction", "axis point [m]", "pitch [m/rad]", "clip"];
    if (verdicts) head.push("finite?");
    const table = el("table", { class: "pinmob-motions" }, [el("tr", {}, head.map((h) => el("th", { text: h })))]);
    if (!doc.motions.length) {
      table.appendChild(el("tr", {}, [el("td", { colspan: String(head.length), text: "none: " + doc.subject + " cannot move here (rigid)." })]));
    }
    for (const m of doc.motions) {
      const swatch = el("span", { class: "pinmob-swatch", style: "background:" + m.color });
      const cells = [
        el("td", { class: "label" }, [swatch, m.label]),
        el("td", { class: "kind", text: m.kind_word }),
        el("td", { class: "direction", text: vec(m.direction) }),
        el("td", { class: "point", text: m.point ? vec(m.point) : "–" }),
        el("td", { class: "pitch", text: m.kind === "T" ? "–" : fmt(m.pitch) }),
        el("td", { class: "clip", text: clipCell(m) }),
      ];
      if (verdicts) cells.push(el("td", { class: "verdict", text: m.verdict || "–" }));
      const row = el("tr", { class: "pinmob-motion", "data-label": m.label, title: "play " + m.label }, cells);
      row.addEventListener("click", () => pinmob.select(m.label));
      table.appendChild(row);
      const text = m.clip_text + (m.why.length ? " — " + m.why.join("; ") : "");
      const detail = el("td", { colspan: String(head.length) }, [el("span", { class: "pinmob-reason", text: text })]);
      if (m.notes.length) {
        detail.appendChild(
          el("details", {}, [el("summary", { text: "details" }), ...m.notes.map((n) => el("div", { text: n }))]),
        );
      }
      table.appendChild(el("tr", { class: "pinmob-why" + (m.status === "full" ? " ok" : ""), "data-label": m.label }, [detail]));
    }
    return table;
  }

  function wrenchTable(doc) {
    const table = el("table", { class: "pinmob-wrenches" }, [
      el("tr", {}, ["wrench", "direction", "line through (world) [m]"].map((h) => el("th", { text: h }))),
    ]);
    for (const c of doc.constraints) {
      const swatch = el("span", { class: "pinmob-swatch", style: "background:" + c.color });
      table.appendChild(
        el("tr", { class: "pinmob-wrench", "data-name": c.name }, [
          el("td", {}, [swatch, c.name]),
          el("td", { text: vec(c.direction) }),
          el("td", { text: c.point ? vec(c.point) : "– (a couple has no line)" }),
        ]),
      );
    }
    return table;
  }

  // a scan's reachable set (pinmob/viewer/workspace.py): counts, the colour scale with its ends, the marks
  function workspaceBlock(ws) {
    const scale = ws.scale;
    const bar = el("div", { class: "pinmob-scale-bar", style: "background:linear-gradient(to right," + scale.colors.join(",") + ")" });
    const ends = el("div", { class: "pinmob-scale-ends" }, [
      el("span", { text: fmt(scale.lo, 3) }),
      el("span", { text: fmt(Math.sqrt(scale.lo * scale.hi), 3) }),
      el("span", { text: fmt(scale.hi, 3) }),
    ]);
    return el("div", { class: "pinmob-workspace" }, [
      el("h2", { text: "Workspace: " + ws.count + " of " + ws.total + " samples assembled" }),
      ws.title ? el("div", { class: "pinmob-note", text: ws.title }) : "",
      ...ws.axes.map((a) => el("div", { class: "pinmob-note", text: a })),
      el("div", { class: "pinmob-note", text: ws.points }),
      bar,
      ends,
      el("div", { class: "pinmob-scale-words", text: "colour: " + scale.words }),
      ...ws.marks.map((m) => el("div", { class: "pinmob-mark" }, [el("span", { class: "pinmob-swatch round", style: "background:" + m.color }), m.text])),
    ]);
  }

  function toggle(id, text, checked, onChange) {
    const box = el("input", { type: "checkbox", id: id });
    box.checked = checked;
    box.addEventListener("change", () => onChange(box.checked));
    return el("label", { for: id }, [box, " " + text]);
  }

  pinmob.show = function (viewer, doc) {
    for (const old of document.querySelectorAll("#pinmob-panel, #pinmob-labels")) old.remove();
    const answer = el("div", { class: "pinmob-answer" }, [
      doc.subject.charAt(0).toUpperCase() + doc.subject.slice(1) + " has ",
      el("b", { class: "pinmob-dof", text: doc.answer.dof + " DoF" }),
      ": ",
      el("b", { class: "pinmob-type", text: doc.answer.motion_type }),
      doc.answer.words ? " (" + doc.answer.words + ")" : "",
    ]);
    const collapse = el("button", { type: "button", title: "hide or show the panel", text: "hide" });
    const wrenchBlock = el("div", { class: "pinmob-wrench-block" }, [
      el("h2", { text: "Constraint wrenches (rank " + doc.constraint_rank + "): what stops the other motions" }),
      doc.constraints.length ? wrenchTable(doc) : el("div", { class: "pinmob-note", text: "none: " + doc.subject + " is free." }),
    ]);
    wrenchBlock.style.display = doc.wrenches_drawn ? "" : "none";
    const legend = el(
      "div",
      { class: "pinmob-legend" },
      doc.legend.map((item) =>
        el("div", {}, [el("span", { class: "pinmob-icon", style: "color:" + item.color, text: item.icon }), item.text]),
      ),
    );
    const panel = el("div", { id: "pinmob-panel" }, [
      el("div", { class: "pinmob-head" }, [el("h1", { text: doc.title }), collapse]),
      answer,
      ...doc.summary.map((line) => el("div", { class: "pinmob-note", text: line })),
      doc.workspace ? workspaceBlock(doc.workspace) : "",
      el("h2", { text: "Free motions: click one to play it" }),
      motionTable(doc),
      el("div", { class: "pinmob-playing", text: doc.motions.length ? "" : "Nothing to play: no free motion." }),
      el("h2", { text: "Singularity" }),
      el("div", { class: "pinmob-singularity", text: doc.singularity }),
      el("h2", { text: "Whole mechanism" }),
      el("div", { class: "pinmob-mechanism", text: doc.mechanism }),
      doc.minimal_closures ? el("h2", { text: "Minimal closures" }) : "",
      ...(doc.minimal_closures || []).map((line) => el("div", { class: "pinmob-minimal", text: line })),
      wrenchBlock,
      el("h2", { text: "Legend" }),
      legend,
      el("div", { class: "pinmob-toggles" }, [
        toggle("pinmob-world", "world axes and grid", doc.world.visible, (on) => {
          setVisible(viewer, doc.world.path, on);
          pinmob.state.showWorld = on;
        }),
        toggle("pinmob-wrench-toggle", "constraint wrenches", doc.wrenches_drawn, (on) => {
          setVisible(viewer, doc.wrench_path, on);
          wrenchBlock.style.display = on ? "" : "none";
          pinmob.state.showWrenches = on;
        }),
        doc.workspace
          ? toggle("pinmob-workspace-toggle", "workspace points", true, (on) => setVisible(viewer, doc.workspace.path, on))
          : "",
        toggle("pinmob-label-toggle", "labels", true, (on) => {
          pinmob.state.showLabels = on;
        }),
      ]),
      el("div", { class: "pinmob-foot", text: doc.footer }),
    ]);
    collapse.addEventListener("click", () => {
      panel.classList.toggle("collapsed");
      collapse.textContent = panel.classList.contains("collapsed") ? "show" : "hide";
      frame();
    });
    document.body.appendChild(panel);
    const layer = el("div", { id: "pinmob-labels" });
    document.body.appendChild(layer);
    const labels = doc.glyphs.map((glyph) => {
      const node = el("div", {
        class: "pinmob-label " + glyph.group,
        "data-label": glyph.label,
        style: "color:" + glyph.color,
        text: glyph.text || glyph.label,
      });
      if (glyph.group === "motion") node.addEventListener("click", () => pinmob.select(glyph.label));
      layer.appendChild(node);
      return { glyph: glyph, node: node };
    });
    pinmob.state = {
      viewer, doc, panel, labels, selected: null,
      showWorld: doc.world.visible, showWrenches: doc.wrenches_drawn, showLabels: true,
    };
    setVisible(viewer, doc.world.path, doc.world.visible);

    // the view: the orbit target in the middle of what the panel leaves visible, everything still in view
    function frame() {
      const canvas = viewer.renderer.domElement;
      const w = canvas.clientWidth, h = canvas.clientHeight;
      if (!w || !h) return;
      const covered = Math.min(panel.offsetWidth + 16, 0.6 * w);
      viewer.camera.setViewOffset(w, h, -covered / 2, 0, w, h);
      viewer.camera.zoom = Math.min(1, (w - covered) / h);
      viewer.camera.updateProjectionMatrix();
      viewer.set_dirty();
    }
    frame();
    window.addEventListener("resize", frame);
    if (doc.visible) pinmob.select(doc.visible);
    if (!pinmob.looping) {
      pinmob.looping = true;
      requestAnimationFrame(placeLabels);
    }
  };

  // every frame: each label at the screen projection of its anchor (pinmob's world is the /pinmob node's frame),
  // hidden with its glyph or behind the camera, then pushed down until it overlaps no label placed before it
  function placeLabels() {
    requestAnimationFrame(placeLabels);
    const state = pinmob.state;
    if (!state) return;
    const { viewer } = state;
    const root = viewer.scene_tree.find(["meshcat", "pinmob"]).object;
    root.updateMatrixWorld(true);
    viewer.camera.updateMatrixWorld();
    const rect = viewer.renderer.domElement.getBoundingClientRect();
    const placed = [];
    const boxes = [];
    for (const box of state.labels) {
      const group = box.glyph.group;
      let show = state.showLabels || group === "world";
      if (group === "world") show = state.showWorld;
      if (group === "wrench") show = show && state.showWrenches;
      const v = viewer.camera.position.clone().set(...box.glyph.anchor);
      v.applyMatrix4(root.matrixWorld).project(viewer.camera);
      if (!show || v.z > 1 || !root.visible) {
        box.node.style.display = "none";
        continue;
      }
      box.node.style.display = "";
      boxes.push({ box, x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height });
    }
    boxes.sort((a, b) => a.y - b.y);
    for (const item of boxes) {
      const w = item.box.node.offsetWidth, h = item.box.node.offsetHeight;
      let y = item.y;
      for (let moved = true, guard = 0; moved && guard < 50; guard++) {
        moved = false;
        for (const p of placed) {
          if (Math.abs(item.x - p.x) < (w + p.w) / 2 + 2 && Math.abs(y - p.y) < (h + p.h) / 2 + 1) {
            y = p.y + (h + p.h) / 2 + 2;
            moved = true;
          }
        }
      }
      placed.push({ x: item.x, y: y, w: w, h: h });
      item.box.node.style.left = item.x.toFixed(1) + "px";
      item.box.node.style.top = y.toFixed(1) + "px";
    }
  }
})();
