// A game controller in the browser as ROS's joy_node: the Gamepad API polled, sensor_msgs/Joy published
// through the gateway. The signs follow joy_node (up and left positive: the browser reports a stick
// pushed up as -1, the Linux joystick API as -32767, and joy_node flips both), buttons are 0/1, and a
// message goes out on every change and again every `repeat` ms while a button or stick is held, so
// teleop_twist_joy keeps the robot moving and stops it as soon as the enable button is let go.
const DEADZONE = 0.05;

function scaled(v, deadzone) {
  // joy_node's dead zone: cut out around the centre, the rest rescaled to reach +-1
  if (Math.abs(v) <= deadzone) return 0;
  return -(v - Math.sign(v) * deadzone) / (1 - deadzone);
}

export function startGamepad(ros, { topic = "joy", frameId = "browser_gamepad", repeat = 50, deadzone = DEADZONE, status } = {}) {
  let pub = null;
  let last = "";
  let lastSent = 0;
  const state = { id: null, published: 0 };
  function poll() {
    const pads = navigator.getGamepads ? Array.from(navigator.getGamepads()).filter(Boolean) : [];
    const pad = pads[0];
    if (!pad) {
      if (state.id !== null) { state.id = null; if (status) status(null); }
      return;
    }
    if (state.id !== pad.id) { state.id = pad.id; if (status) status(pad.id); }
    const axes = Array.from(pad.axes, (v) => scaled(v, deadzone));
    const buttons = Array.from(pad.buttons, (b) => (b.pressed ? 1 : 0));
    const key = JSON.stringify([axes, buttons]);
    const held = buttons.some((b) => b) || axes.some((a) => a !== 0);
    const now = performance.now();
    if (key === last && !(held && now - lastSent >= repeat)) return;
    last = key;
    lastSent = now;
    if (!pub) pub = ros.advertise(topic, "sensor_msgs/Joy");
    const secs = Date.now() / 1000;
    pub.publish({
      header: { seq: 0, stamp: { secs: Math.floor(secs), nsecs: Math.round((secs % 1) * 1e9) }, frame_id: frameId },
      axes, buttons,
    });
    state.published += 1;
  }
  const timer = setInterval(poll, 20);
  window.addEventListener("gamepadconnected", poll);
  window.addEventListener("gamepaddisconnected", poll);
  return { state, stop: () => clearInterval(timer) };
}
