// Loads a glTF file with three.js's GLTFLoader, plays each animation with an
// AnimationMixer set to the times given, and prints what three.js sees as
// one JSON object: the skinned meshes with their skeletons, and at each time
// every bone's world matrix, every vertex of every skinned mesh as the
// skinning puts it, and the world matrix of every segment node (nodes rig).
// The test suite compares them with liganimate's --poses.
// Usage: node three_pose.mjs <three package folder> FILE TIME...
import fs from 'fs';
import path from 'path';
import {pathToFileURL} from 'url';

const threeDir = path.resolve(process.argv[2]);
const THREE = await import(pathToFileURL(path.join(threeDir, 'build', 'three.module.js')).href);
const {GLTFLoader} = await import(pathToFileURL(path.join(threeDir, 'examples', 'jsm', 'loaders', 'GLTFLoader.js')).href);

const file = process.argv[3];
const times = process.argv.slice(4).map(Number);
const bytes = fs.readFileSync(file);
const data = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);

const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(data, '', resolve, reject));

const out = {scenes: [], animations: gltf.animations.map((c) => ({name: c.name, duration: c.duration}))};
for (const [s, scene] of gltf.scenes.entries()) {
  const skinned = [];
  scene.traverse((o) => { if (o.isSkinnedMesh) skinned.push(o); });
  const bones = [];
  scene.traverse((o) => { if (o.isBone) bones.push(o); });
  // GLTFLoader keeps an animation's name but sanitizes a scene's ("scene 1" becomes "scene_1").
  const clip = gltf.animations.find((c) => THREE.PropertyBinding.sanitizeNodeName(c.name) === scene.name);
  const mixer = new THREE.AnimationMixer(scene);
  if (clip) mixer.clipAction(clip).play();
  const record = {
    name: scene.name,
    bones: bones.map((b) => b.name),
    skinned: skinned.map((m) => ({
      name: m.name,
      skeleton: m.skeleton.bones.map((b) => b.name),
      skeletonExtras: m.skeleton.bones.map((b) => b.userData),
      vertices: m.geometry.attributes.position.count,
    })),
    ticks: [],
  };
  for (const t of times) {
    mixer.setTime(t);
    scene.updateMatrixWorld(true);
    const tick = {time: t, skinned: [], segments: []};
    // The nodes rig's segment nodes: their world matrices.
    scene.traverse((o) => {
      const info = o.userData.liganimate;
      if (info && info.segment !== undefined && !info.bone) {
        tick.segments.push({model: info.model, segment: info.segment, matrix: Array.from(o.matrixWorld.elements)});
      }
    });
    // Meshes with morph targets outside a skin (the nodes rig's shape nodes): their vertices, morphed.
    tick.morphed = [];
    scene.traverse((o) => {
      if (o.isMesh && !o.isSkinnedMesh && o.morphTargetInfluences) {
        const pos = o.geometry.attributes.position;
        const v = new THREE.Vector3();
        const flat = new Array(pos.count * 3);
        for (let i = 0; i < pos.count; i++) {
          o.getVertexPosition(i, v);  // morphed, in the mesh's space
          v.applyMatrix4(o.matrixWorld);
          flat[3 * i] = v.x; flat[3 * i + 1] = v.y; flat[3 * i + 2] = v.z;
        }
        tick.morphed.push({name: o.name, vertices: flat});
      }
    });
    for (const m of skinned) {
      const world = m.skeleton.bones.map((b) => Array.from(b.matrixWorld.elements));
      m.skeleton.update();
      const pos = m.geometry.attributes.position;
      const v = new THREE.Vector3();
      const flat = new Array(pos.count * 3);
      for (let i = 0; i < pos.count; i++) {
        m.getVertexPosition(i, v);  // skinned, in the mesh's space
        v.applyMatrix4(m.matrixWorld);
        flat[3 * i] = v.x; flat[3 * i + 1] = v.y; flat[3 * i + 2] = v.z;
      }
      tick.skinned.push({bones: world, vertices: flat});
    }
    record.ticks.push(tick);
  }
  out.scenes.push(record);
}
console.log(JSON.stringify(out));
